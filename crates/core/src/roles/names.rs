//! Roles by joint name: one table per naming scheme (the only list of joint names in the project),
//! and the spelling rules every scheme shares (namespace and `DEF-` prefixes, sides written in any
//! case as Left/Right, L/R, l/r, `.L`/`.R`, `_l`/`_r`, `left_`, …).

use super::{Role, Scheme, Side};
use crate::Skeleton;

/// How a scheme writes the side of a joint, for the fixtures' names ([`Scheme::joint_name`]);
/// matching accepts every spelling whatever the scheme.
#[derive(Clone, Copy)]
enum SideStyle {
    /// Side word before the name: `LeftArm`, `lShldr`, `CC_Base_L_Thigh`, `left_knee`.
    Prefix(&'static str, &'static str),
    /// Side word after the name: `upperarm_l`, `upper_arm.L`.
    Suffix(&'static str, &'static str),
}

/// One naming scheme: the central joints' full names and the sided joints' names without their side
/// word, best first. Names are compared after [`normalize`] (case, separators, prefixes ignored).
struct Table {
    scheme: Scheme,
    side: SideStyle,
    /// Written before every central name in the fixtures (`mixamorig:`).
    prefix: &'static str,
    hips: &'static [&'static str],
    head: &'static [&'static str],
    clavicle: &'static [&'static str],
    upper_arm: &'static [&'static str],
    forearm: &'static [&'static str],
    hand: &'static [&'static str],
    thigh: &'static [&'static str],
    shin: &'static [&'static str],
    foot: &'static [&'static str],
    toe: &'static [&'static str],
}

impl Table {
    fn names(&self, role: Role) -> &'static [&'static str] {
        match role {
            Role::Hips => self.hips,
            Role::Head => self.head,
            Role::Clavicle(_) => self.clavicle,
            Role::UpperArm(_) => self.upper_arm,
            Role::Forearm(_) => self.forearm,
            Role::Hand(_) => self.hand,
            Role::Thigh(_) => self.thigh,
            Role::Shin(_) => self.shin,
            Role::Foot(_) => self.foot,
            Role::Toe(_) => self.toe,
            Role::Spine | Role::Chest | Role::Neck => &[],
        }
    }
}

/// Every scheme, in the order ties between equally good matches are settled.
const TABLES: &[Table] = &[
    // MotionBuilder / HumanIK names, also Mixamo's (after its `mixamorig:` namespace) and the
    // cgspeed CMU BVH conversion's.
    Table {
        scheme: Scheme::HumanIk,
        side: SideStyle::Prefix("Left", "Right"),
        prefix: "",
        hips: &["Hips"],
        head: &["Head"],
        clavicle: &["Shoulder"],
        upper_arm: &["Arm"],
        forearm: &["ForeArm"],
        hand: &["Hand"],
        thigh: &["UpLeg"],
        shin: &["Leg"],
        foot: &["Foot"],
        toe: &["ToeBase"],
    },
    Table {
        scheme: Scheme::Mixamo,
        side: SideStyle::Prefix("mixamorig:Left", "mixamorig:Right"),
        prefix: "mixamorig:",
        hips: &["Hips"],
        head: &["Head"],
        clavicle: &["Shoulder"],
        upper_arm: &["Arm"],
        forearm: &["ForeArm"],
        hand: &["Hand"],
        thigh: &["UpLeg"],
        shin: &["Leg"],
        foot: &["Foot"],
        toe: &["ToeBase"],
    },
    // The cgspeed CMU release for 3ds Max (subjects 131–140).
    Table {
        scheme: Scheme::CmuMax,
        side: SideStyle::Prefix("Left", "Right"),
        prefix: "",
        hips: &["Hips"],
        head: &["Head"],
        clavicle: &["Collar"],
        upper_arm: &["Shoulder"],
        forearm: &["Elbow"],
        hand: &["Wrist"],
        thigh: &["Hip"],
        shin: &["Knee"],
        foot: &["Ankle"],
        toe: &["Toe"],
    },
    Table {
        scheme: Scheme::CmuAsf,
        side: SideStyle::Prefix("l", "r"),
        prefix: "",
        hips: &["root"],
        head: &["head"],
        clavicle: &["clavicle"],
        upper_arm: &["humerus"],
        forearm: &["radius"],
        hand: &["wrist"],
        thigh: &["femur"],
        shin: &["tibia"],
        foot: &["foot"],
        toe: &["toes"],
    },
    Table {
        scheme: Scheme::Unity,
        side: SideStyle::Prefix("Left", "Right"),
        prefix: "",
        hips: &["Hips"],
        head: &["Head"],
        clavicle: &["Shoulder"],
        upper_arm: &["UpperArm"],
        forearm: &["LowerArm"],
        hand: &["Hand"],
        thigh: &["UpperLeg"],
        shin: &["LowerLeg"],
        foot: &["Foot"],
        toe: &["Toes"],
    },
    // Genesis 3/8 split limbs into Bend and Twist joints; Genesis 1/2 did not.
    Table {
        scheme: Scheme::Daz,
        side: SideStyle::Prefix("l", "r"),
        prefix: "",
        hips: &["hip", "pelvis"],
        head: &["head"],
        clavicle: &["Collar"],
        upper_arm: &["ShldrBend", "Shldr"],
        forearm: &["ForearmBend", "ForeArm"],
        hand: &["Hand"],
        thigh: &["ThighBend", "Thigh"],
        shin: &["Shin"],
        foot: &["Foot"],
        toe: &["Metatarsals", "Toe"],
    },
    Table {
        scheme: Scheme::CharacterCreator,
        side: SideStyle::Prefix("CC_Base_L_", "CC_Base_R_"),
        prefix: "CC_Base_",
        hips: &["Hip", "Pelvis"],
        head: &["Head"],
        clavicle: &["Clavicle"],
        upper_arm: &["Upperarm"],
        forearm: &["Forearm"],
        hand: &["Hand"],
        thigh: &["Thigh"],
        shin: &["Calf"],
        foot: &["Foot"],
        toe: &["ToeBase"],
    },
    Table {
        scheme: Scheme::Unreal,
        side: SideStyle::Suffix("_l", "_r"),
        prefix: "",
        hips: &["pelvis"],
        head: &["head"],
        clavicle: &["clavicle"],
        upper_arm: &["upperarm"],
        forearm: &["lowerarm"],
        hand: &["hand"],
        thigh: &["thigh"],
        shin: &["calf"],
        foot: &["foot"],
        toe: &["ball"],
    },
    // Blender's human metarig and the rig Rigify makes from it (`DEF-` deform bones).
    Table {
        scheme: Scheme::Rigify,
        side: SideStyle::Suffix(".L", ".R"),
        prefix: "",
        hips: &["spine"],
        head: &["spine.006", "head"],
        clavicle: &["shoulder"],
        upper_arm: &["upper_arm"],
        forearm: &["forearm"],
        hand: &["hand"],
        thigh: &["thigh"],
        shin: &["shin"],
        foot: &["foot"],
        toe: &["toe"],
    },
    Table {
        scheme: Scheme::Biped,
        side: SideStyle::Prefix("Bip01 L ", "Bip01 R "),
        prefix: "Bip01 ",
        hips: &["Pelvis"],
        head: &["Head"],
        clavicle: &["Clavicle"],
        upper_arm: &["UpperArm"],
        forearm: &["Forearm"],
        hand: &["Hand"],
        thigh: &["Thigh"],
        shin: &["Calf"],
        foot: &["Foot"],
        toe: &["Toe0"],
    },
    Table {
        scheme: Scheme::Smpl,
        side: SideStyle::Prefix("left_", "right_"),
        prefix: "",
        hips: &["pelvis"],
        head: &["head"],
        clavicle: &["collar"],
        upper_arm: &["shoulder"],
        forearm: &["elbow"],
        hand: &["wrist"],
        thigh: &["hip"],
        shin: &["knee"],
        foot: &["ankle"],
        toe: &["foot"],
    },
];

impl Scheme {
    /// This scheme's name for a joint playing `role` (its first spelling), as the fixtures write it;
    /// `None` for the roles a scheme leaves to the hierarchy (spine, chest, neck).
    pub fn joint_name(self, role: Role) -> Option<String> {
        let t = TABLES.iter().find(|t| t.scheme == self).or(TABLES.first())?;
        let base = *t.names(role).first()?;
        Some(match (role.side(), t.side) {
            (None, _) => format!("{}{base}", t.prefix),
            (Some(s), SideStyle::Prefix(l, r)) => format!("{}{base}", if s == Side::Left { l } else { r }),
            (Some(s), SideStyle::Suffix(l, r)) => format!("{}{base}{}", t.prefix, if s == Side::Left { l } else { r }),
        })
    }
}

/// Lower case letters and digits of `name` after its namespace (`mixamorig:`, a Maya path), a
/// Rigify `DEF-` prefix, and the `CC_Base_` and `Bip01` prefixes.
pub(crate) fn normalize(name: &str) -> String {
    let rest = strip_prefixes(name);
    rest.chars().filter(|c| c.is_ascii_alphanumeric()).map(|c| c.to_ascii_lowercase()).collect()
}

fn strip_prefixes(name: &str) -> &str {
    let mut s = name.rsplit([':', '|']).next().unwrap_or(name);
    let lower = s.to_ascii_lowercase();
    // `mixamorig_` where an exporter replaced the colon; `mixamorig1` etc. for a second import.
    if let Some(after) = lower.strip_prefix("mixamorig") {
        let digits = after.chars().take_while(|c| c.is_ascii_digit()).count();
        let skip = "mixamorig".len() + digits + usize::from(after[digits..].starts_with(['_', '-', ' ']));
        s = &s[skip..];
    }
    for p in ["def-", "def_", "cc_base_"] {
        if s.len() > p.len() && s.to_ascii_lowercase().starts_with(p) {
            s = &s[p.len()..];
        }
    }
    // 3ds Max Biped: `Bip01 L UpperArm`, `Bip001_Pelvis`.
    let l = s.to_ascii_lowercase();
    if let Some(after) = l.strip_prefix("bip") {
        let digits = after.chars().take_while(|c| c.is_ascii_digit()).count();
        if digits > 0 && after[digits..].starts_with([' ', '_', '-']) {
            s = &s[3 + digits + 1..];
        }
    }
    s
}

/// The ways `name` can be read as a side and the rest of the name (normalized): a separate side
/// token anywhere (`upperarm_l`, `upper_arm.L.001`, `L_Thigh`), a `Left`/`Right` word in front
/// (`LeftArm`, `left_shoulder`), or one letter in front (`lShldr`, `LHipJoint`, `lhumerus`).
pub(crate) fn sided(name: &str) -> Vec<(Side, String)> {
    let s = strip_prefixes(name);
    let side_of = |t: &str| match t.to_ascii_lowercase().as_str() {
        "l" | "left" => Some(Side::Left),
        "r" | "right" => Some(Side::Right),
        _ => None,
    };
    let norm = |t: &str| -> String {
        t.chars().filter(|c| c.is_ascii_alphanumeric()).map(|c| c.to_ascii_lowercase()).collect()
    };
    let mut out = Vec::new();
    let tokens: Vec<&str> = s.split(['_', '.', '-', ' ']).filter(|t| !t.is_empty()).collect();
    for (i, t) in tokens.iter().enumerate() {
        if let Some(side) = side_of(t) {
            let rest: String = tokens.iter().enumerate().filter(|(k, _)| *k != i).map(|(_, t)| norm(t)).collect();
            out.push((side, rest));
        }
    }
    let lower = s.to_ascii_lowercase();
    for (word, side) in [("left", Side::Left), ("right", Side::Right)] {
        if lower.len() > word.len() && lower.starts_with(word) {
            out.push((side, norm(&s[word.len()..])));
        }
    }
    let mut chars = s.chars();
    if let (Some(first), Some(second)) = (chars.next(), chars.next()) {
        if let Some(side) = side_of(&first.to_string()) {
            if second.is_ascii_alphabetic() {
                out.push((side, norm(&s[1..])));
            }
        }
    }
    out
}

/// The best scheme's name matches: for each role the joint nearest the root among those its names
/// match, with the scheme and how many of the required roles it matched.
pub(crate) struct NameMatch {
    pub scheme: Scheme,
    pub found: Vec<(Role, usize)>,
}

/// Matches every scheme against `skeleton` and keeps the one that names the most roles (the
/// required ones first); `None` when no scheme names any joint.
pub(crate) fn by_name(skeleton: &Skeleton) -> Option<NameMatch> {
    let depth = depths(skeleton);
    let central: Vec<String> = skeleton.joints().iter().map(|j| normalize(&j.name)).collect();
    let sides: Vec<Vec<(Side, String)>> = skeleton.joints().iter().map(|j| sided(&j.name)).collect();
    let mut best: Option<(usize, usize, NameMatch)> = None;
    for t in TABLES {
        let mut found = Vec::new();
        for role in Role::ALL {
            let names: Vec<String> = t.names(role).iter().map(|n| normalize(n)).collect();
            // Earlier spellings win over later ones, then the joint nearest the root.
            let hit = names.iter().find_map(|n| {
                (0..skeleton.len())
                    .filter(|&j| match role.side() {
                        None => &central[j] == n,
                        Some(s) => sides[j].iter().any(|(js, rest)| *js == s && rest == n),
                    })
                    .min_by_key(|&j| (depth[j], j))
            });
            if let Some(j) = hit {
                found.push((role, j));
            }
        }
        // A joint named for two roles (`Hip` as hips and, with a side word read into it, thigh)
        // keeps the first.
        let mut used = Vec::new();
        found.retain(|(_, j)| {
            let fresh = !used.contains(j);
            used.push(*j);
            fresh
        });
        let required = found.iter().filter(|(r, _)| r.required()).count();
        let better = best.as_ref().is_none_or(|(br, bt, _)| (required, found.len()) > (*br, *bt));
        if !found.is_empty() && better {
            best = Some((required, found.len(), NameMatch { scheme: t.scheme, found }));
        }
    }
    let (_, _, mut m) = best?;
    m.scheme = refine(m.scheme, skeleton);
    Some(m)
}

/// Schemes that share their names told apart by what else the skeleton holds.
fn refine(scheme: Scheme, skeleton: &Skeleton) -> Scheme {
    if scheme != Scheme::HumanIk {
        return scheme;
    }
    let names: Vec<String> = skeleton.joints().iter().map(|j| j.name.to_ascii_lowercase()).collect();
    if names.iter().any(|n| n.starts_with("mixamorig")) {
        Scheme::Mixamo
    } else if names.iter().any(|n| n == "lowerback" || n == "lhipjoint") {
        Scheme::CmuBvh
    } else {
        Scheme::HumanIk
    }
}

pub(crate) fn depths(skeleton: &Skeleton) -> Vec<usize> {
    let mut d = vec![0usize; skeleton.len()];
    for (i, j) in skeleton.joints().iter().enumerate() {
        if let Some(p) = j.parent {
            d[i] = d[p] + 1;
        }
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sides_are_read_in_every_spelling() {
        for (name, side, rest) in [
            ("LeftArm", Side::Left, "arm"),
            ("mixamorig1:RightForeArm", Side::Right, "forearm"),
            ("lShldrBend", Side::Left, "shldrbend"),
            ("CC_Base_R_Upperarm", Side::Right, "upperarm"),
            ("upperarm_l", Side::Left, "upperarm"),
            ("DEF-upper_arm.R", Side::Right, "upperarm"),
            ("thigh.l", Side::Left, "thigh"),
            ("Bip01 L UpperArm", Side::Left, "upperarm"),
            ("left_shoulder", Side::Left, "shoulder"),
            ("RIGHT_HAND", Side::Right, "hand"),
            ("lhumerus", Side::Left, "humerus"),
        ] {
            let got = sided(name);
            assert!(got.iter().any(|(s, r)| *s == side && r == rest), "{name}: {got:?}");
        }
        assert_eq!(normalize("mixamorig:Hips"), "hips");
        assert_eq!(normalize("Bip001 Pelvis"), "pelvis");
        assert_eq!(normalize("DEF-spine.006"), "spine006");
        // A Rigify twist segment keeps its number, so it is not read as the limb itself.
        assert!(sided("DEF-upper_arm.L.001").iter().all(|(_, r)| r != "upperarm"));
    }
}
