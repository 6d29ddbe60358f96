//! Skeletons for testing role finding on rigs the project has no files of: a humanoid renamed to any
//! [`Scheme`] (sides included), to bare names (`j0`, `j1`, …: shape only), with its joints listed
//! right side first, turned to face −Z, given extra twist and finger joints; and two non-humanoids.

use super::{find_roles, Role, RoleOverrides, Scheme};
use crate::rotation::EulerOrder;
use crate::{Channel, Joint, Motion, Skeleton};
use glam::DVec3;

fn readable(s: &Skeleton) -> super::Roles {
    find_roles(s, &RoleOverrides::default()).expect("a fixture's source skeleton has roles")
}

fn with_names(s: &Skeleton, name: impl Fn(usize) -> String) -> Skeleton {
    let joints = s.joints().iter().enumerate().map(|(i, j)| Joint { name: name(i), ..j.clone() }).collect();
    Skeleton::new(joints).expect("renaming keeps a valid skeleton")
}

/// `s` with its role joints named as `scheme` names them and every other joint `x<index>` (after
/// the scheme's namespace, if it has one).
pub fn renamed(s: &Skeleton, scheme: Scheme) -> Skeleton {
    let roles = readable(s);
    let prefix =
        scheme.joint_name(Role::Hips).map(|h| h.rsplit_once(':').map(|(p, _)| format!("{p}:")).unwrap_or_default());
    with_names(s, |i| {
        roles
            .role_of(i)
            .and_then(|r| scheme.joint_name(r))
            .unwrap_or_else(|| format!("{}x{i}", prefix.clone().unwrap_or_default()))
    })
}

/// `s` with joints named `j0`, `j1`, … in file order.
pub fn bare(s: &Skeleton) -> Skeleton {
    with_names(s, |i| format!("j{i}"))
}

/// A clip on another skeleton with the same layout (renamed joints).
pub fn with_skeleton(m: &Motion, s: Skeleton) -> Motion {
    assert_eq!(s.num_channels(), m.skeleton.num_channels(), "same channel layout");
    Motion::new(s, m.frame_time, m.data().to_vec()).expect("same channel layout")
}

/// The clip with each joint's children listed in reverse order (the right limbs before the left
/// ones in the file), channels moved along; the motion itself is unchanged.
pub fn reordered(m: &Motion) -> Motion {
    let s = &m.skeleton;
    let mut order = Vec::with_capacity(s.len());
    let mut stack = vec![0usize];
    while let Some(j) = stack.pop() {
        order.push(j);
        // Pushed in file order, so popped in reverse: the last child is listed first.
        stack.extend(s.children(j));
    }
    let mut new_index = vec![0usize; s.len()];
    for (k, &j) in order.iter().enumerate() {
        new_index[j] = k;
    }
    let joints: Vec<Joint> =
        order.iter().map(|&j| Joint { parent: s.parent(j).map(|p| new_index[p]), ..s.joint(j).clone() }).collect();
    let skeleton = Skeleton::new(joints).expect("a depth-first order keeps parents first");
    let mut data = Vec::with_capacity(m.data().len());
    for f in 0..m.num_frames() {
        let frame = m.frame(f);
        for &j in &order {
            let (a, n) = (s.channel_start(j), s.joint(j).channels.len());
            data.extend_from_slice(&frame[a..a + n]);
        }
    }
    Motion::new(skeleton, m.frame_time, data).expect("same channels, moved")
}

/// `s` turned half a turn about +Y: it faces −Z, its left side at −X.
pub fn turned(s: &Skeleton) -> Skeleton {
    let flip = |v: DVec3| DVec3::new(-v.x, v.y, -v.z);
    let joints = s
        .joints()
        .iter()
        .map(|j| Joint { offset: flip(j.offset), end_site: j.end_site.map(flip), ..j.clone() })
        .collect();
    Skeleton::new(joints).expect("turning keeps a valid skeleton")
}

/// `s` with a twist joint halfway along each upper arm, forearm and thigh (in the limb's chain, as
/// Daz and Rigify have them), a leaf twist bone beside each upper arm and thigh (as Unreal and
/// Character Creator have them), and five three-joint fingers on each hand.
pub fn with_extras(s: &Skeleton) -> Skeleton {
    let roles = readable(s);
    let rot = Channel::rotations(EulerOrder::Zyx).to_vec();
    let bone = |name: String, parent: usize, offset: DVec3, end: Option<DVec3>| Joint {
        name,
        parent: Some(parent),
        offset,
        channels: rot.clone(),
        end_site: end,
    };
    let mut out: Vec<Joint> = Vec::new();
    let mut new_index = vec![0usize; s.len()];
    for (i, j) in s.joints().iter().enumerate() {
        let mut joint = Joint { parent: j.parent.map(|p| new_index[p]), ..j.clone() };
        let role = roles.role_of(i);
        // In-chain twist: inserted between this joint and its parent, halfway.
        if let (Some(Role::Forearm(_) | Role::Hand(_) | Role::Shin(_)), Some(p)) = (role, joint.parent) {
            out.push(bone(format!("{}_twist_chain", out[p].name), p, joint.offset * 0.5, None));
            joint.parent = Some(out.len() - 1);
            joint.offset *= 0.5;
        }
        new_index[i] = out.len();
        out.push(joint);
        let me = new_index[i];
        let child_offset = s.children(i).map(|c| s.joint(c).offset).max_by(|a, b| a.length().total_cmp(&b.length()));
        match (role, child_offset) {
            (Some(Role::UpperArm(_) | Role::Thigh(_)), Some(d)) => {
                out.push(bone(format!("{}_twist_leaf", s.joint(i).name), me, d * 0.3, Some(d * 0.01)));
            }
            (Some(Role::Hand(_)), _) => {
                let along = j.offset.try_normalize().unwrap_or(DVec3::NEG_Y) * j.offset.length().max(1e-6);
                let across = along.cross(DVec3::Z).try_normalize().unwrap_or(DVec3::X) * along.length();
                for f in 0..5 {
                    let spread = (f as f64 - 2.0) * 0.08;
                    let mut parent = me;
                    for k in 0..3 {
                        let off = if k == 0 { along * 0.35 + across * spread } else { along * 0.1 };
                        let end = (k == 2).then_some(along * 0.08);
                        out.push(bone(format!("{}_finger{f}_{k}", s.joint(i).name), parent, off, end));
                        parent = out.len() - 1;
                    }
                }
            }
            _ => {}
        }
    }
    Skeleton::new(out).expect("extras keep a valid skeleton")
}

fn build(parts: &[(&str, Option<&str>, [f64; 3])]) -> Skeleton {
    let rot = Channel::rotations(EulerOrder::Zyx).to_vec();
    let mut joints: Vec<Joint> = Vec::new();
    for (name, parent, offset) in parts {
        let parent = parent.map(|p| joints.iter().position(|j| j.name == p).expect("parent first"));
        joints.push(Joint {
            name: name.to_string(),
            parent,
            offset: DVec3::from(*offset),
            channels: rot.clone(),
            end_site: None,
        });
    }
    Skeleton::new(joints).expect("a valid fixture")
}

/// A four-legged animal (hind legs at the root, front legs from the shoulders, a neck and head),
/// with bare names.
pub fn quadruped() -> Skeleton {
    let mut parts: Vec<(String, Option<String>, [f64; 3])> = vec![("j0".into(), None, [0.0, 60.0, 0.0])];
    let mut add = |parent: &str, offset: [f64; 3]| {
        let name = format!("j{}", parts.len());
        parts.push((name.clone(), Some(parent.to_string()), offset));
        name
    };
    let back = add("j0", [0.0, 0.0, 30.0]);
    let shoulders = add(&back, [0.0, 0.0, 30.0]);
    let neck = add(&shoulders, [0.0, 15.0, 15.0]);
    add(&neck, [0.0, 10.0, 10.0]);
    for (root, x) in [("j0", 10.0), ("j0", -10.0), (shoulders.as_str(), 10.0), (shoulders.as_str(), -10.0)] {
        let a = add(root, [x, -5.0, 0.0]);
        let b = add(&a, [0.0, -27.0, 0.0]);
        let c = add(&b, [0.0, -25.0, 0.0]);
        add(&c, [0.0, -2.0, 6.0]);
    }
    let refs: Vec<(&str, Option<&str>, [f64; 3])> =
        parts.iter().map(|(n, p, o)| (n.as_str(), p.as_deref(), *o)).collect();
    build(&refs)
}

/// A ten-joint chain (a tail or a tentacle).
pub fn chain() -> Skeleton {
    let names: Vec<String> = (0..10).map(|i| format!("bone{i}")).collect();
    let parts: Vec<(&str, Option<&str>, [f64; 3])> = (0..10)
        .map(|i| {
            (names[i].as_str(), (i > 0).then(|| names[i - 1].as_str()), [0.0, if i == 0 { 0.0 } else { 10.0 }, 0.0])
        })
        .collect();
    build(&parts)
}

/// The joints of every role the skeleton `s` has, as `(role, joint name)`, for comparing two rigs.
pub fn role_names(s: &Skeleton) -> Vec<(Role, String)> {
    let roles = readable(s);
    roles.roles.iter().map(|(r, a)| (*r, a.name.clone())).collect()
}
