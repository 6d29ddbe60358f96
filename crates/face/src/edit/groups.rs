//! Blendshape groups, so an edit can touch only part of the face (e.g. only the mouth) and leave
//! every other curve exactly as it was.

use crate::data::{ARKIT_NAMES, NUM_ARKIT};

/// A named set of ARKit shapes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Group {
    /// `EyeBlink*`, `EyeLook*`, `EyeSquint*`, `EyeWide*`.
    Eyes,
    /// `BrowDown*`, `BrowInnerUp`, `BrowOuterUp*`.
    Brows,
    /// `Jaw*`.
    Jaw,
    /// `Mouth*`.
    Mouth,
    /// `CheekPuff`, `CheekSquint*`, `NoseSneer*`.
    Cheeks,
    /// `TongueOut`.
    Tongue,
}

impl Group {
    /// Every group, in the order of [`Group::name`]'s list.
    pub const ALL: [Group; 6] = [Group::Eyes, Group::Brows, Group::Jaw, Group::Mouth, Group::Cheeks, Group::Tongue];

    /// Lower-case name used on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Group::Eyes => "eyes",
            Group::Brows => "brows",
            Group::Jaw => "jaw",
            Group::Mouth => "mouth",
            Group::Cheeks => "cheeks",
            Group::Tongue => "tongue",
        }
    }

    /// The group a shape belongs to.
    pub fn of_shape(name: &str) -> Group {
        let n = name.to_ascii_lowercase();
        if n.starts_with("eye") {
            Group::Eyes
        } else if n.starts_with("brow") {
            Group::Brows
        } else if n.starts_with("jaw") {
            Group::Jaw
        } else if n.starts_with("mouth") {
            Group::Mouth
        } else if n.starts_with("tongue") {
            Group::Tongue
        } else {
            Group::Cheeks
        }
    }

    /// Whether ARKit shape `i` is in this group.
    pub fn contains(self, i: usize) -> bool {
        i < NUM_ARKIT && Group::of_shape(ARKIT_NAMES[i]) == self
    }
}

/// Parse a comma-separated group list: group names, `lower` (jaw, mouth, cheeks, tongue), `upper`
/// (eyes, brows) or `all`. Returns the per-shape selection, or a message naming the bad word.
pub fn parse_groups(list: &str) -> Result<[bool; NUM_ARKIT], String> {
    let mut on = [false; NUM_ARKIT];
    for word in list.split(',').map(str::trim).filter(|w| !w.is_empty()) {
        let groups: Vec<Group> = match word.to_ascii_lowercase().as_str() {
            "all" => Group::ALL.to_vec(),
            "lower" => vec![Group::Jaw, Group::Mouth, Group::Cheeks, Group::Tongue],
            "upper" => vec![Group::Eyes, Group::Brows],
            w => match Group::ALL.iter().find(|g| g.name() == w) {
                Some(g) => vec![*g],
                None => {
                    return Err(format!(
                        "unknown blendshape group '{word}'; expected a comma-separated list of {}, lower, upper or all",
                        Group::ALL.map(|g| g.name()).join(", ")
                    ))
                }
            },
        };
        for g in groups {
            for (i, flag) in on.iter_mut().enumerate() {
                *flag |= g.contains(i);
            }
        }
    }
    if !on.iter().any(|b| *b) {
        return Err(format!("empty blendshape group list '{list}'; expected e.g. 'mouth,jaw'"));
    }
    Ok(on)
}

/// The groups speech moves, which viseme guidance (text, TextGrid, phoneme timings) drives when the
/// edit names no groups: jaw, mouth, cheeks (and nose), tongue.
pub const SPEECH_GROUPS: [Group; 4] = [Group::Jaw, Group::Mouth, Group::Cheeks, Group::Tongue];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::arkit_index;

    #[test]
    fn groups_partition_the_shapes() {
        for (i, name) in ARKIT_NAMES.iter().enumerate() {
            assert_eq!(Group::ALL.iter().filter(|g| g.contains(i)).count(), 1, "{name}");
        }
        let counts: Vec<usize> = Group::ALL.iter().map(|g| (0..NUM_ARKIT).filter(|i| g.contains(*i)).count()).collect();
        assert_eq!(counts, vec![14, 5, 4, 23, 5, 1]);
    }

    #[test]
    fn lists_parse_and_bad_words_are_named() {
        let m = parse_groups("mouth, jaw").unwrap();
        assert!(m[arkit_index("JawOpen").unwrap()] && m[arkit_index("MouthClose").unwrap()]);
        assert!(!m[arkit_index("EyeBlinkLeft").unwrap()]);
        assert_eq!(parse_groups("all").unwrap(), [true; NUM_ARKIT]);
        let err = parse_groups("mouth,nose").unwrap_err();
        assert!(err.contains("'nose'"), "{err}");
        assert!(parse_groups(" , ").is_err());
    }
}
