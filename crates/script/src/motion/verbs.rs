//! Verb table for template-action retrieval (§3.2, §4.2): each canonical action tag with the verb
//! lemmas (and description words) that name it.

/// Canonical tag and the lemmas that retrieve it. The canonical tag is listed first among its own
/// words. Order matters only for [`canonical`] ties (first table entry wins).
pub const VERBS: &[(&str, &[&str])] = &[
    (
        "walk",
        &[
            "walk", "stroll", "stride", "march", "wander", "go", "move", "step", "pace", "amble", "limp", "come",
            "approach", "head", "sneak", "enter", "leave", "exit", "follow", "return", "arrive", "stumble", "shuffle",
            "tiptoe", "creep",
        ],
    ),
    ("run", &["run", "jog", "sprint", "race", "dash", "rush", "hurry", "chase", "escape"]),
    ("jump", &["jump", "hop", "leap", "bound", "skip"]),
    ("sit", &["sit", "seat", "perch"]),
    ("sit_down", &["sit_down"]),
    ("stand_up", &["stand_up", "rise", "get_up", "wake", "wake_up"]),
    (
        "stand",
        &[
            "stand", "idle", "stay", "wait", "stop", "remain", "rest", "pause", "balance", "tremble", "shiver",
            "freeze", "huddle", "lurk",
        ],
    ),
    ("lie", &["lie", "lie_down", "sleep", "nap", "collapse", "faint", "fall"]),
    ("punch", &["punch", "box", "strike", "hit", "jab", "fight", "swordplay", "sword", "spar", "block", "dodge"]),
    ("kick", &["kick"]),
    ("dance", &["dance", "waltz", "salsa", "pirouette", "twirl", "spin", "arabesque", "jete"]),
    ("wave", &["wave", "greet", "beckon", "signal", "welcome", "meet", "clap", "applaud", "cheer", "conduct"]),
    ("climb", &["climb", "scale", "ascend", "hang", "dangle"]),
    (
        "reach",
        &[
            "reach", "grab", "pick", "take", "push", "press", "touch", "pull", "lift", "scoop", "open", "fetch",
            "close", "shut", "put", "place", "set", "drop", "give", "hand", "pass", "offer", "point", "indicate",
            "hold", "carry", "lay", "pour", "fill", "load", "cover", "light", "grip", "clutch", "show", "accept",
            "catch", "bring", "lock", "unlock", "plug", "charge", "switch", "flip", "sort", "count",
        ],
    ),
    (
        "type",
        &[
            "type", "play", "use", "operate", "work", "tap", "text", "dribble", "shoot", "dial", "record", "strum",
            "tune",
        ],
    ),
    (
        "call",
        &[
            "call", "phone", "talk", "speak", "chat", "tell", "say", "sing", "shout", "ask", "answer", "cry", "laugh",
            "scream", "whisper", "mutter", "yell", "hum", "whistle", "teach", "explain", "discuss", "present",
            "perform", "refuse", "sob", "weep",
        ],
    ),
    ("drink", &["drink", "sip", "eat", "blow"]),
    (
        "look",
        &[
            "look", "watch", "see", "stare", "gaze", "observe", "view", "listen", "examine", "read", "glance", "peek",
            "peer", "squint", "notice", "spot", "inspect", "admire", "browse", "check", "search", "find", "hear",
            "study",
        ],
    ),
    (
        "think",
        &[
            "think",
            "ponder",
            "wonder",
            "consider",
            "contemplate",
            "pray",
            "sigh",
            "yawn",
            "relax",
            "frown",
            "blink",
            "shrug",
            "smile",
            "nod",
            "feel",
        ],
    ),
    ("write", &["write", "draw", "paint", "sketch", "design", "compose", "sew"]),
    (
        "hammer",
        &[
            "hammer",
            "saw",
            "nail",
            "chop",
            "serve",
            "build",
            "wash",
            "cook",
            "clean",
            "sweep",
            "fix",
            "repair",
            "cut",
            "stir",
            "fold",
            "bang",
            "barricade",
            "board",
            "smash",
            "break",
            "knock",
            "slam",
            "tear",
        ],
    ),
    ("bend", &["bend", "crouch", "squat", "kneel", "stoop", "lean", "bow", "curtsy"]),
    ("throw", &["throw", "toss", "pitch", "aim"]),
    ("turn", &["turn", "rotate", "face"]),
];

/// Verbs done to or with another person, who the character turns to ("talks to Ben", "waves at
/// Mia"); "they talk" makes each of a group talk to the next.
pub fn social(lemma: &str) -> bool {
    matches!(
        lemma,
        "talk"
            | "speak"
            | "chat"
            | "say"
            | "tell"
            | "ask"
            | "answer"
            | "laugh"
            | "shout"
            | "whisper"
            | "argue"
            | "look"
            | "watch"
            | "stare"
            | "gaze"
            | "glance"
            | "listen"
            | "wave"
            | "greet"
            | "nod"
            | "smile"
            | "face"
    )
}

/// The canonical tag of a verb lemma (lower-cased; a plural/-ing/-ed form is tried as a fallback,
/// though lemmatising is the caller's job).
pub fn canonical(lemma: &str) -> Option<&'static str> {
    let w = lemma.trim().to_ascii_lowercase().replace([' ', '-'], "_");
    if w.is_empty() {
        return None;
    }
    let find = |w: &str| VERBS.iter().find(|(_, syn)| syn.contains(&w)).map(|(c, _)| *c);
    if let Some(c) = find(&w) {
        return Some(c);
    }
    let stems =
        [w.strip_suffix("ing"), w.strip_suffix("es"), w.strip_suffix('s'), w.strip_suffix("ed"), w.strip_suffix('d')];
    for s in stems.into_iter().flatten() {
        for cand in [s.to_string(), format!("{s}e"), undouble(s)] {
            if let Some(c) = find(&cand) {
                return Some(c);
            }
        }
    }
    None
}

fn undouble(s: &str) -> String {
    let b = s.as_bytes();
    if b.len() >= 2 && b[b.len() - 1] == b[b.len() - 2] {
        s[..s.len() - 1].to_string()
    } else {
        s.to_string()
    }
}

/// Canonical tags named in a CMU trial description ("playground - forward jumps, turn around" →
/// jump, turn), in order of appearance, without duplicates.
pub fn tags_of_description(description: &str) -> Vec<String> {
    // Split camelCase names ("AttitudeWalk") into words.
    let mut spaced = String::with_capacity(description.len() + 8);
    let mut prev_lower = false;
    for ch in description.chars() {
        if ch.is_ascii_uppercase() && prev_lower {
            spaced.push(' ');
        }
        prev_lower = ch.is_ascii_lowercase();
        spaced.push(ch);
    }
    let lower = spaced.to_ascii_lowercase();
    let mut tags: Vec<String> = Vec::new();
    let mut push = |t: &str| {
        if !tags.iter().any(|x| x == t) {
            tags.push(t.to_string());
        }
    };
    // Phrases first: they would be misread word by word.
    for (phrase, tag) in [
        ("sit down", "sit_down"),
        ("stand up", "stand_up"),
        ("get up", "stand_up"),
        ("jumping jack", "jump"),
        ("bend over", "bend"),
    ] {
        if lower.contains(phrase) {
            push(tag);
        }
    }
    for word in lower.split(|c: char| !c.is_ascii_alphabetic()).filter(|w| w.len() > 1) {
        // Description words that are nouns of an activity.
        let t = match word {
            "boxing" | "punching" => Some("punch"),
            "basketball" => Some("type"),
            "soccer" => Some("kick"),
            "playground" | "around" | "forward" | "backward" | "sideways" | "up" | "down" => None,
            w => canonical(w),
        };
        if let Some(t) = t {
            push(t);
        }
    }
    tags
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lemmas_and_forms() {
        assert_eq!(canonical("walk"), Some("walk"));
        assert_eq!(canonical("Jogging"), Some("run"));
        assert_eq!(canonical("sits"), Some("sit"));
        assert_eq!(canonical("punched"), Some("punch"));
        assert_eq!(canonical("frobnicate"), None);
        assert_eq!(canonical(""), None);
    }

    #[test]
    fn descriptions() {
        assert_eq!(tags_of_description("playground - forward jumps, turn around"), vec!["jump", "turn"]);
        assert_eq!(tags_of_description("run/jog"), vec!["run"]);
        assert_eq!(tags_of_description("punch/strike"), vec!["punch"]);
        assert_eq!(tags_of_description("Start Walk Stop"), vec!["walk", "stand"]);
    }
}
