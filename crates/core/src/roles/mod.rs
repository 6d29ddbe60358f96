//! Joint roles of a humanoid skeleton (hips, spine, chest, neck, head and, per side, clavicle,
//! upper arm, forearm, hand, thigh, shin, foot, toe), found on any rig in one place that every
//! engine and front end uses:
//! 1. by name, for the schemes people meet ([`Scheme`]: CMU BVH and ASF, Mixamo under any
//!    namespace, HumanIK, Unity, Daz Genesis, Character Creator, Unreal's mannequin, Rigify and
//!    Blender's metarig, 3ds Max Biped, SMPL), sides spelled in any way;
//! 2. by shape where names do not settle it ([`shape`]: limbs as chains from the hips and the chest,
//!    sides from the rest pose), each role with a confidence;
//! 3. from a roles file ([`RoleOverrides`]: role → joint name), which wins over both.
//!
//! The spine, chest and neck come from the hierarchy between the roles found: the chest is where
//! the arms meet, the spine the joints from the hips up to it, the neck those from it to the head.
//!
//! ```
//! use inbetween_core::procedural::standard_skeleton;
//! use inbetween_core::roles::{find_roles, How, Role, RoleOverrides, Scheme, Side};
//! let s = standard_skeleton();
//! let roles = find_roles(&s, &RoleOverrides::default()).unwrap();
//! assert_eq!(s.joint(roles.joint(Role::UpperArm(Side::Left))).name, "LeftArm");
//! assert_eq!(roles.how(Role::Hips), Some(How::Name(Scheme::CmuBvh)));
//! ```

mod names;
mod shape;

pub mod fixtures;

use crate::{Motion, Skeleton};
use glam::DVec3;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::fmt;

/// A side of the body, the character's own (its left hand is on its left).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Side {
    Left,
    Right,
}

impl Side {
    pub const BOTH: [Side; 2] = [Side::Left, Side::Right];

    pub fn word(self) -> &'static str {
        match self {
            Side::Left => "left",
            Side::Right => "right",
        }
    }
}

/// What a joint does in a humanoid body.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Role {
    Hips,
    /// The lowest joint of the spine above the hips.
    Spine,
    /// The spine joint the arms branch from.
    Chest,
    /// The lowest joint between the chest and the head.
    Neck,
    Head,
    Clavicle(Side),
    UpperArm(Side),
    Forearm(Side),
    Hand(Side),
    Thigh(Side),
    Shin(Side),
    Foot(Side),
    Toe(Side),
}

impl Role {
    /// Every role, central ones first, then left and right limbs.
    pub const ALL: [Role; 21] = [
        Role::Hips,
        Role::Spine,
        Role::Chest,
        Role::Neck,
        Role::Head,
        Role::Clavicle(Side::Left),
        Role::UpperArm(Side::Left),
        Role::Forearm(Side::Left),
        Role::Hand(Side::Left),
        Role::Thigh(Side::Left),
        Role::Shin(Side::Left),
        Role::Foot(Side::Left),
        Role::Toe(Side::Left),
        Role::Clavicle(Side::Right),
        Role::UpperArm(Side::Right),
        Role::Forearm(Side::Right),
        Role::Hand(Side::Right),
        Role::Thigh(Side::Right),
        Role::Shin(Side::Right),
        Role::Foot(Side::Right),
        Role::Toe(Side::Right),
    ];

    pub fn side(self) -> Option<Side> {
        match self {
            Role::Hips | Role::Spine | Role::Chest | Role::Neck | Role::Head => None,
            Role::Clavicle(s)
            | Role::UpperArm(s)
            | Role::Forearm(s)
            | Role::Hand(s)
            | Role::Thigh(s)
            | Role::Shin(s)
            | Role::Foot(s)
            | Role::Toe(s) => Some(s),
        }
    }

    fn part(self) -> &'static str {
        match self {
            Role::Hips => "hips",
            Role::Spine => "spine",
            Role::Chest => "chest",
            Role::Neck => "neck",
            Role::Head => "head",
            Role::Clavicle(_) => "clavicle",
            Role::UpperArm(_) => "upper_arm",
            Role::Forearm(_) => "forearm",
            Role::Hand(_) => "hand",
            Role::Thigh(_) => "thigh",
            Role::Shin(_) => "shin",
            Role::Foot(_) => "foot",
            Role::Toe(_) => "toe",
        }
    }

    /// The role's key in a roles file: `hips`, `left_upper_arm`, `right_toe`.
    pub fn key(self) -> String {
        match self.side() {
            Some(s) => format!("{}_{}", s.word(), self.part()),
            None => self.part().to_string(),
        }
    }

    /// A role from its key (case, `-` and spaces ignored: `Left-Upper-Arm` works).
    pub fn parse(key: &str) -> Option<Role> {
        let k = key.trim().to_ascii_lowercase().replace(['-', ' '], "_");
        Role::ALL.into_iter().find(|r| r.key() == k)
    }

    /// Roles every humanoid must have; the rest (clavicles, toes, and the spine, chest and neck,
    /// which the hierarchy gives) may be absent.
    pub fn required(self) -> bool {
        !matches!(self, Role::Spine | Role::Chest | Role::Neck | Role::Clavicle(_) | Role::Toe(_))
    }
}

impl fmt::Display for Role {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.key())
    }
}

impl Serialize for Role {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.key())
    }
}

impl<'de> Deserialize<'de> for Role {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Role, D::Error> {
        let key = String::deserialize(d)?;
        Role::parse(&key).ok_or_else(|| {
            serde::de::Error::custom(format!("unknown role '{key}'; roles are {}", role_keys().join(", ")))
        })
    }
}

fn role_keys() -> Vec<String> {
    Role::ALL.iter().map(|r| r.key()).collect()
}

/// A naming scheme joints are matched by.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Scheme {
    /// cgspeed's BVH conversion of CMU mocap (MotionBuilder names, `LowerBack`, `LHipJoint`).
    CmuBvh,
    /// cgspeed's 3ds Max-friendly CMU release (`LeftCollar`, `LeftShoulder` as the upper arm).
    CmuMax,
    /// CMU's own ASF skeletons (`lhumerus`, `lfemur`).
    CmuAsf,
    /// Mixamo (`mixamorig:LeftArm`, any namespace).
    Mixamo,
    /// MotionBuilder HumanIK (`LeftArm`, `LeftUpLeg`).
    HumanIk,
    /// Unity's humanoid avatar names (`LeftUpperArm`, `LeftLowerLeg`).
    Unity,
    /// Daz Genesis (`lShldrBend`, `lThigh`, `abdomenLower`).
    Daz,
    /// Character Creator and iClone (`CC_Base_L_Upperarm`).
    CharacterCreator,
    /// Unreal's mannequin (`upperarm_l`, `thigh_r`).
    Unreal,
    /// Rigify and Blender's metarig (`upper_arm.L`, `DEF-thigh.R`).
    Rigify,
    /// 3ds Max Biped (`Bip01 L UpperArm`).
    Biped,
    /// SMPL, SMPL-X and AMASS (`left_shoulder`, `left_knee`).
    Smpl,
}

impl Scheme {
    pub const ALL: [Scheme; 12] = [
        Scheme::CmuBvh,
        Scheme::CmuMax,
        Scheme::CmuAsf,
        Scheme::Mixamo,
        Scheme::HumanIk,
        Scheme::Unity,
        Scheme::Daz,
        Scheme::CharacterCreator,
        Scheme::Unreal,
        Scheme::Rigify,
        Scheme::Biped,
        Scheme::Smpl,
    ];

    pub fn label(self) -> &'static str {
        match self {
            Scheme::CmuBvh => "CMU BVH",
            Scheme::CmuMax => "CMU BVH (3ds Max release)",
            Scheme::CmuAsf => "CMU ASF",
            Scheme::Mixamo => "Mixamo",
            Scheme::HumanIk => "HumanIK",
            Scheme::Unity => "Unity humanoid",
            Scheme::Daz => "Daz Genesis",
            Scheme::CharacterCreator => "Character Creator",
            Scheme::Unreal => "Unreal mannequin",
            Scheme::Rigify => "Rigify",
            Scheme::Biped => "3ds Max Biped",
            Scheme::Smpl => "SMPL",
        }
    }
}

/// How a role's joint was found.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum How {
    /// Its name, in this scheme.
    Name(Scheme),
    /// The skeleton's shape in its rest pose.
    Shape,
    /// The hierarchy between other roles (spine, chest, neck).
    Chain,
    /// The roles file.
    Override,
}

impl fmt::Display for How {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            How::Name(s) => write!(f, "name ({})", s.label()),
            How::Shape => f.write_str("shape"),
            How::Chain => f.write_str("between the roles found"),
            How::Override => f.write_str("roles file"),
        }
    }
}

/// One role's joint.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Assigned {
    pub joint: usize,
    pub name: String,
    pub how: How,
    /// 1 for names and the roles file; for the shape, how clearly the rest pose told (the sides
    /// from toes and a wide stance: 1; facing +Z assumed for want of toes: 0.6).
    pub confidence: f64,
}

/// Role → joint name, from a roles file (`{"left_upper_arm": "lShldrBend", …}`); wins over names
/// and shape.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct RoleOverrides {
    pub joints: BTreeMap<Role, String>,
}

/// Why no roles could be given.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum RolesError {
    /// Required roles were found neither by name nor by shape.
    #[error(
        "not a humanoid skeleton this can read: no joint found for {}; by name: {by_name}; by shape: {by_shape}. \
         Name the joints in a roles file given as `roles` (JSON, role → joint name, e.g. {{\"{}\": \"<joint>\"}}; \
         roles: {})",
        missing.iter().map(|r| r.key()).collect::<Vec<_>>().join(", "),
        missing.first().map(|r| r.key()).unwrap_or_default(),
        role_keys().join(", ")
    )]
    Missing { missing: Vec<Role>, by_name: String, by_shape: String },
    /// A roles file names a joint the skeleton lacks.
    #[error("the roles file gives '{joint}' for {role}, but the skeleton has no joint of that name")]
    NoSuchJoint { role: Role, joint: String },
    /// The roles found contradict the hierarchy (a hand not below its forearm).
    #[error("{0}; name the joints in a roles file given as `roles`")]
    Inconsistent(String),
}

/// The roles of one skeleton.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Roles {
    pub roles: BTreeMap<Role, Assigned>,
    /// From the hips (excluded) up to the chest (included).
    pub spine: Vec<usize>,
    /// From the chest (excluded) up to the head (excluded).
    pub neck: Vec<usize>,
    /// The scheme names matched, if any did.
    pub scheme: Option<Scheme>,
    /// What was assumed on the way (no toes to face by, …).
    pub notes: Vec<String>,
}

impl Roles {
    pub fn get(&self, role: Role) -> Option<usize> {
        self.roles.get(&role).map(|a| a.joint)
    }

    /// The joint of a required role ([`Role::required`]), which [`find_roles`] always gives.
    pub fn joint(&self, role: Role) -> usize {
        match self.get(role) {
            Some(j) => j,
            None => panic!("role {role} is not required, use Roles::get"),
        }
    }

    pub fn how(&self, role: Role) -> Option<How> {
        self.roles.get(&role).map(|a| a.how)
    }

    /// The lowest confidence among the required roles.
    pub fn confidence(&self) -> f64 {
        self.roles.iter().filter(|(r, _)| r.required()).map(|(_, a)| a.confidence).fold(1.0, f64::min)
    }

    /// The role a joint plays, if any.
    pub fn role_of(&self, joint: usize) -> Option<Role> {
        self.roles.iter().find(|(_, a)| a.joint == joint).map(|(r, _)| *r)
    }

    /// `[clavicle or upper arm, upper arm, forearm, hand]` of one side (the clavicle slot holds the
    /// upper arm when the rig has none).
    pub fn arm(&self, side: Side) -> [usize; 4] {
        let upper = self.joint(Role::UpperArm(side));
        [
            self.get(Role::Clavicle(side)).unwrap_or(upper),
            upper,
            self.joint(Role::Forearm(side)),
            self.joint(Role::Hand(side)),
        ]
    }

    /// The hand's longest finger chain below it (CMU: `LeftFingerBase`, `LeftHandIndex1`), empty
    /// when the hand has no children.
    pub fn finger_chain(&self, skeleton: &Skeleton, side: Side) -> Vec<usize> {
        let reach = shape_reach(skeleton);
        let through = |c: usize| skeleton.joint(c).offset.length() + reach[c];
        let mut out = Vec::new();
        let mut cur = self.get(Role::Hand(side));
        while let Some(next) = cur.and_then(|c| skeleton.children(c).max_by(|&a, &b| through(a).total_cmp(&through(b))))
        {
            out.push(next);
            cur = Some(next);
        }
        out
    }

    /// The end of [`Roles::finger_chain`] (CMU: `LeftHandIndex1`).
    pub fn fingertip(&self, skeleton: &Skeleton, side: Side) -> Option<usize> {
        self.finger_chain(skeleton, side).last().copied()
    }
}

fn shape_reach(s: &Skeleton) -> Vec<f64> {
    let mut reach = vec![0.0f64; s.len()];
    for i in (0..s.len()).rev() {
        let own = s.joint(i).end_site.map(|e| e.length()).unwrap_or(0.0);
        reach[i] = s.children(i).map(|c| s.joint(c).offset.length() + reach[c]).fold(own, f64::max);
    }
    reach
}

impl fmt::Display for Roles {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let width = self.roles.values().map(|a| a.name.len()).max().unwrap_or(0);
        for (role, a) in &self.roles {
            write!(f, "  {:<15} {:<width$}  {}", role.key(), a.name, a.how)?;
            if a.how == How::Shape {
                write!(f, ", confidence {:.2}", a.confidence)?;
            }
            writeln!(f)?;
        }
        for n in &self.notes {
            writeln!(f, "  note: {n}")?;
        }
        Ok(())
    }
}

/// The roles of a clip's skeleton: [`find_roles`] on its rest pose, and where that pose is no
/// standing one (Character Creator's BVH files model their legs pointing up with all channels at
/// zero, and stand in a T-pose in frame 0), the shape read in its first frame.
pub fn find_motion_roles(motion: &Motion, overrides: &RoleOverrides) -> Result<Roles, RolesError> {
    match find_roles(&motion.skeleton, overrides) {
        Err(e @ RolesError::Missing { .. }) if motion.num_frames() > 0 => {
            let g = crate::fk::forward(&motion.skeleton, &motion.pose(0));
            let mut r = find_roles_posed(&motion.skeleton, Some(&g.positions), overrides).map_err(|posed| {
                match (e, posed) {
                    (
                        RolesError::Missing { missing, by_name, by_shape },
                        RolesError::Missing { by_shape: in_pose, .. },
                    ) => {
                        RolesError::Missing { missing, by_name, by_shape: format!("{by_shape}; in frame 0, {in_pose}") }
                    }
                    (_, other) => other,
                }
            })?;
            r.notes.push("shape read in frame 0 (the rest pose is not a standing one)".into());
            Ok(r)
        }
        other => other,
    }
}

/// The roles of `skeleton`: the roles file first, then names, then the shape for whatever is still
/// missing; the spine, chest and neck from the hierarchy between them.
pub fn find_roles(skeleton: &Skeleton, overrides: &RoleOverrides) -> Result<Roles, RolesError> {
    find_roles_posed(skeleton, None, overrides)
}

/// [`find_roles`] reading the shape in the pose of these global joint positions (the rest pose
/// when `None`).
pub fn find_roles_posed(
    skeleton: &Skeleton,
    posed: Option<&[DVec3]>,
    overrides: &RoleOverrides,
) -> Result<Roles, RolesError> {
    let name_of = |j: usize| skeleton.joint(j).name.clone();
    let mut roles: BTreeMap<Role, Assigned> = BTreeMap::new();
    let mut taken = vec![false; skeleton.len()];
    let mut put = |roles: &mut BTreeMap<Role, Assigned>, role: Role, joint: usize, how: How, confidence: f64| {
        if !roles.contains_key(&role) && !taken[joint] {
            taken[joint] = true;
            roles.insert(role, Assigned { joint, name: name_of(joint), how, confidence });
        }
    };
    for (role, name) in &overrides.joints {
        let j = skeleton.find(name).ok_or_else(|| RolesError::NoSuchJoint { role: *role, joint: name.clone() })?;
        put(&mut roles, *role, j, How::Override, 1.0);
    }
    let named = names::by_name(skeleton);
    let scheme = named.as_ref().map(|m| m.scheme);
    if let Some(m) = &named {
        for &(role, j) in &m.found {
            put(&mut roles, role, j, How::Name(m.scheme), 1.0);
        }
    }
    let limb_roles = |r: &Role| !matches!(r, Role::Spine | Role::Chest | Role::Neck);
    let mut notes = Vec::new();
    let mut shape_error = String::from("not needed");
    if Role::ALL.iter().filter(|r| limb_roles(r)).any(|r| !roles.contains_key(r)) {
        match shape::by_shape(skeleton, posed) {
            Ok(s) => {
                for (role, j, c) in s.found {
                    put(&mut roles, role, j, How::Shape, c);
                }
                if roles.values().any(|a| a.how == How::Shape) {
                    notes.extend(s.notes);
                }
            }
            Err(e) => shape_error = e,
        }
    }
    let missing: Vec<Role> = Role::ALL.into_iter().filter(|r| r.required() && !roles.contains_key(r)).collect();
    if !missing.is_empty() {
        let by_name = match &named {
            Some(m) => format!("the names read best as {} ({} roles)", m.scheme.label(), m.found.len()),
            None => "no joint is named as in a known scheme".to_string(),
        };
        return Err(RolesError::Missing { missing, by_name, by_shape: shape_error });
    }
    check_limbs(skeleton, &roles)?;
    // The chest: where the two arms meet; the spine and neck: the paths to it and on to the head.
    let hips = roles[&Role::Hips].joint;
    let head = roles[&Role::Head].joint;
    let arm_root = |s: Side| roles.get(&Role::Clavicle(s)).unwrap_or(&roles[&Role::UpperArm(s)]).joint;
    let chest = common_ancestor(skeleton, arm_root(Side::Left), arm_root(Side::Right));
    let spine = path_below(skeleton, hips, chest);
    let neck = path_below(skeleton, chest, head).map(|mut p| {
        p.pop();
        p
    });
    let (Some(spine), Some(neck)) = (spine, neck) else {
        return Err(RolesError::Inconsistent(format!(
            "the arms meet at '{}', which is not between the hips '{}' and the head '{}'",
            name_of(chest),
            name_of(hips),
            name_of(head)
        )));
    };
    let chain_conf = roles.values().map(|a| a.confidence).fold(1.0, f64::min);
    let mut chain = |role: Role, j: Option<&usize>| {
        if let Some(&j) = j {
            roles.entry(role).or_insert(Assigned {
                joint: j,
                name: name_of(j),
                how: How::Chain,
                confidence: chain_conf,
            });
        }
    };
    chain(Role::Spine, spine.first());
    chain(Role::Chest, spine.last());
    chain(Role::Neck, neck.first());
    Ok(Roles { roles, spine, neck, scheme, notes })
}

/// For each joint of the `target` skeleton, the `source` joint that plays its part: the same role,
/// the same place in the spine and neck chains (by index, spread evenly when the lengths differ),
/// and else the joint of the same name (case aside: CMU's ASF `lthumb` is its BVH `LThumb`). With
/// `detail`, also the links between the hips and each thigh and the hand's longest finger chain, by
/// index (a retargeter that corrects each bone towards its mapped children may want fingers left to
/// follow the hand).
pub fn correspondence(target: (&Skeleton, &Roles), source: (&Skeleton, &Roles), detail: bool) -> Vec<Option<usize>> {
    let ((ts, tr), (ss, sr)) = (target, source);
    let mut map: Vec<Option<usize>> = vec![None; ts.len()];
    let chain = |t: &[usize], s: &[usize], map: &mut Vec<Option<usize>>| {
        for (k, &j) in t.iter().enumerate() {
            let at = if t.len() == s.len() || t.len() < 2 {
                k
            } else {
                (k as f64 * (s.len() as f64 - 1.0) / (t.len() as f64 - 1.0)).round() as usize
            };
            if let Some(&sj) = s.get(at) {
                map[j] = Some(sj);
            }
        }
    };
    chain(&tr.spine, &sr.spine, &mut map);
    chain(&tr.neck, &sr.neck, &mut map);
    if detail {
        for side in Side::BOTH {
            let (th, sh) = (tr.get(Role::Hips), sr.get(Role::Hips));
            let (tt, st) = (tr.get(Role::Thigh(side)), sr.get(Role::Thigh(side)));
            if let (Some(th), Some(sh), Some(tt), Some(st)) = (th, sh, tt, st) {
                let links = |s: &Skeleton, h: usize, t: usize| {
                    let mut p = path_below(s, h, t).unwrap_or_default();
                    p.pop();
                    p
                };
                chain(&links(ts, th, tt), &links(ss, sh, st), &mut map);
            }
            let (tf, sf) = (tr.finger_chain(ts, side), sr.finger_chain(ss, side));
            let n = tf.len().min(sf.len());
            chain(&tf[..n], &sf[..n], &mut map);
        }
    }
    for (j, joint) in ts.joints().iter().enumerate() {
        if map[j].is_none() && tr.role_of(j).is_none() {
            let same = ss
                .find(&joint.name)
                .or_else(|| ss.joints().iter().position(|sj| sj.name.eq_ignore_ascii_case(&joint.name)));
            map[j] = same.filter(|&sj| sr.role_of(sj).is_none());
        }
    }
    for (role, a) in &tr.roles {
        map[a.joint] = sr.get(*role);
    }
    map
}

/// Each limb's joints must run down the hierarchy: a name or shape read wrongly shows here.
fn check_limbs(s: &Skeleton, roles: &BTreeMap<Role, Assigned>) -> Result<(), RolesError> {
    for side in Side::BOTH {
        let chains = [
            vec![Role::Hips, Role::Thigh(side), Role::Shin(side), Role::Foot(side), Role::Toe(side)],
            vec![Role::Clavicle(side), Role::UpperArm(side), Role::Forearm(side), Role::Hand(side)],
        ];
        for chain in chains {
            let present: Vec<(Role, &Assigned)> = chain.iter().filter_map(|r| roles.get(r).map(|a| (*r, a))).collect();
            for w in present.windows(2) {
                let ((ra, a), (rb, b)) = (w[0], w[1]);
                if path_below(s, a.joint, b.joint).is_none_or(|p| p.is_empty()) {
                    return Err(RolesError::Inconsistent(format!(
                        "the {} '{}' ({}) is not below the {} '{}' ({})",
                        rb.key().replace('_', " "),
                        b.name,
                        b.how,
                        ra.key().replace('_', " "),
                        a.name,
                        a.how
                    )));
                }
            }
        }
    }
    Ok(())
}

fn ancestors(s: &Skeleton, j: usize) -> Vec<usize> {
    let mut out = vec![j];
    let mut cur = j;
    while let Some(p) = s.parent(cur) {
        out.push(p);
        cur = p;
    }
    out
}

fn common_ancestor(s: &Skeleton, a: usize, b: usize) -> usize {
    let up_a = ancestors(s, a);
    ancestors(s, b).into_iter().find(|j| up_a.contains(j)).unwrap_or(0)
}

/// The joints from `top` (excluded) down to `bottom` (included), `None` when `bottom` is not in
/// `top`'s subtree.
fn path_below(s: &Skeleton, top: usize, bottom: usize) -> Option<Vec<usize>> {
    let up = ancestors(s, bottom);
    let k = up.iter().position(|&j| j == top)?;
    Some(up[..k].iter().rev().copied().collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn role_keys_round_trip_and_unknown_keys_are_refused_with_the_list() {
        for r in Role::ALL {
            assert_eq!(Role::parse(&r.key()), Some(r));
        }
        assert_eq!(Role::parse("Left-Upper-Arm"), Some(Role::UpperArm(Side::Left)));
        let e = serde_json_like_error();
        assert!(e.contains("unknown role 'lefthand'") && e.contains("left_hand"), "{e}");
    }

    fn serde_json_like_error() -> String {
        use serde::de::value::{Error, StrDeserializer};
        use serde::de::IntoDeserializer;
        let d: StrDeserializer<Error> = "lefthand".into_deserializer();
        Role::deserialize(d).unwrap_err().to_string()
    }
}
