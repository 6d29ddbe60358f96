//! Shared test catalogue for the parse tests: every object and room of the paper's captions, so
//! these tests do not depend on the built-in catalogue's contents.

use inbetween_script::catalogue::{Catalogue, Category, RoomKind, Support};

#[allow(dead_code)]
pub fn paper_catalogue() -> Catalogue {
    let c = |name: &str, syn: &[&str]| Category {
        name: name.into(),
        synonyms: syn.iter().map(|s| s.to_string()).collect(),
        size: [1.0, 1.0, 1.0],
        support: Support::Floor,
        surface: false,
        contacts: vec![],
        color: [128, 128, 128],
        model: None,
    };
    let r = |name: &str, syn: &[&str]| RoomKind {
        name: name.into(),
        synonyms: syn.iter().map(|s| s.to_string()).collect(),
        size: [5.0, 2.8, 4.0],
    };
    Catalogue::new(
        vec![
            c("desk", &["officedesk"]),
            c("bed", &[]),
            c("horsesculpture", &[]),
            c("oilpainting", &["painting"]),
            c("sculpture", &[]),
            c("picture", &[]),
            c("blackboard", &[]),
            c("table", &[]),
            c("chair", &["modernchair"]),
            c("boxingring", &[]),
            c("boxingbag", &["punchingbag"]),
            c("stool", &[]),
            c("bottle", &[]),
            c("hammer", &[]),
            c("wood", &[]),
            c("shelf", &["bookshelf"]),
            c("sofa", &["couch"]),
            c("computer", &[]),
            c("recorder", &[]),
            c("piano", &[]),
            c("microphone", &["mic"]),
            c("phone", &["telephone"]),
            c("headphones", &[]),
            c("soda", &[]),
            c("nail", &[]),
            c("laptop", &[]),
            c("house", &[]),
            c("road", &[]),
            c("lamp", &[]),
        ],
        vec![
            r("room", &[]),
            r("office", &[]),
            r("gallery", &[]),
            r("meetingroom", &[]),
            r("workshop", &["workingshop"]),
            r("musicroom", &[]),
            r("livingroom", &[]),
        ],
    )
}
