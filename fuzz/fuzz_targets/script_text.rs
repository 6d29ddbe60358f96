//! Script parser and scene composition on arbitrary text: must never panic (a sentence the rules
//! cannot use becomes a diagnostic). Texts over the job's default limits are refused first, as the
//! CLI refuses them (issue 29), so the parser's work per input is bounded; composition runs on
//! short inputs only, to keep runs fast.
#![no_main]

use std::collections::HashMap;
use std::sync::OnceLock;

use inbetween_script::catalogue::{builtin::builtin, Catalogue};
use inbetween_script::compose::{compose, ComposeConfig, ComposeInput};
use inbetween_script::database::SceneDatabase;
use inbetween_script::limits::ScriptLimits;
use libfuzzer_sys::fuzz_target;

fn world() -> &'static (Catalogue, SceneDatabase) {
    static W: OnceLock<(Catalogue, SceneDatabase)> = OnceLock::new();
    W.get_or_init(|| {
        let cat = builtin();
        let db = SceneDatabase::builtin(&cat, 1, 1);
        (cat, db)
    })
}

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    let (cat, db) = world();
    // The limits' own parse is the one checked further (one parse per input, as the CLI).
    let Ok(parsed) = ScriptLimits::default().check_and_parse(&text, "fuzz input", cat) else {
        return;
    };
    if data.len() <= 400 {
        let pins = HashMap::new();
        let _ = compose(
            &ComposeInput { parsed: &parsed, catalogue: cat, database: db, pins: &pins },
            &ComposeConfig::default(),
        );
    }
});
