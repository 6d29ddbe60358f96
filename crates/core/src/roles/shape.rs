//! Roles from the skeleton's shape in its rest pose, for names no scheme knows: the hips are the
//! joint nearest the root with three long branches (two legs and the spine), the chest the first
//! joint up the spine with two long branches (the arms), the head ends the remaining branch; each
//! limb is read along its longest chain; sides come from the lateral axis (up from the spine,
//! forward from the toes) and never from the file's order.

use super::{Role, Side};
use crate::units::rest_pose_extent;
use crate::Skeleton;
use glam::DVec3;

/// A branch is long when it reaches this fraction of the rest pose's extent (a leg ~0.5, the
/// torso with the head ~0.4, an arm ~0.4, a neck with the head ~0.15, a hand ~0.1).
const LIMB: f64 = 0.25;
/// Shorter than this fraction of the extent, a link is the same place (CMU's `LHipJoint`).
const SAME_PLACE: f64 = 0.02;
/// A child this close (fraction of the extent) whose branches fork is part of the same fork.
const FORK_NEAR: f64 = 0.06;
/// The knee and elbow sit this far along the path from the limb's root joint to its end joint
/// (thigh ≈ shin; upper arm 0.186 and forearm 0.146 of the body height).
const KNEE_AT: f64 = 0.5;
const ELBOW_AT: f64 = 0.56;
/// The link from the ankle on is shorter than this fraction of the leg above the ankle (CMU 0.15,
/// Character Creator 0.14; a twist joint halfway down the shin gives 0.33).
const FOOT_MAX: f64 = 0.25;
/// Fingers reach less than this fraction of the arm above the hand (CMU 0.14, Character Creator 0.3).
const FINGERS_MAX: f64 = 0.5;
/// A clavicle starts closer to the spine's axis than this fraction of the shoulder's distance from it.
const CLAVICLE_MAX: f64 = 0.5;
/// Or it is shorter than this fraction of the arm below it (CMU 0.4, Mixamo 0.2) and bends into
/// the upper arm by more than [`CLAVICLE_BEND`] radians.
const CLAVICLE_SHORT: f64 = 0.5;
const CLAVICLE_BEND: f64 = 0.35;

/// What the shape says: roles with a confidence in 0..=1, and notes on what was assumed.
pub(crate) struct ShapeRoles {
    pub found: Vec<(Role, usize, f64)>,
    pub notes: Vec<String>,
}

struct Geometry<'a> {
    s: &'a Skeleton,
    pos: Vec<DVec3>,
    /// Length of the longest path from each joint down its subtree (to an end site when it has one).
    reach: Vec<f64>,
    /// Children of each joint.
    kids: Vec<Vec<usize>>,
    extent: f64,
}

impl<'a> Geometry<'a> {
    /// The rest pose's geometry, or that of a pose given as global joint positions.
    fn new(s: &'a Skeleton, posed: Option<&[DVec3]>) -> Geometry<'a> {
        let n = s.len();
        let mut pos = vec![DVec3::ZERO; n];
        let mut kids = vec![Vec::new(); n];
        for (i, j) in s.joints().iter().enumerate() {
            if let Some(p) = j.parent {
                pos[i] = pos[p] + j.offset;
                kids[p].push(i);
            }
        }
        let extent = match posed {
            Some(g) => {
                pos = g.iter().map(|&q| q - g[0]).collect();
                let (lo, hi) =
                    pos.iter().fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(l, h), &q| (l.min(q), h.max(q)));
                (hi - lo).max_element()
            }
            None => rest_pose_extent(s),
        };
        let mut reach = vec![0.0f64; n];
        for i in (0..n).rev() {
            let own = s.joint(i).end_site.map(|e| e.length()).unwrap_or(0.0);
            reach[i] = kids[i].iter().map(|&c| s.joint(c).offset.length() + reach[c]).fold(own, f64::max);
        }
        Geometry { s, pos, reach, kids, extent: extent.max(1e-9) }
    }

    /// How far the branch through child `c` reaches from its parent.
    fn through(&self, c: usize) -> f64 {
        self.s.joint(c).offset.length() + self.reach[c]
    }

    fn long_kids(&self, j: usize, fraction: f64) -> Vec<usize> {
        self.kids[j].iter().copied().filter(|&c| self.through(c) >= fraction * self.extent).collect()
    }

    /// The long branches leaving `j`, looking through a child at the same place that forks itself
    /// (Character Creator's legs leave `CC_Base_Pelvis`, a child of `CC_Base_Hip` at its place).
    fn branches(&self, j: usize, fraction: f64) -> Vec<usize> {
        let mut out = Vec::new();
        for c in self.long_kids(j, fraction) {
            let forks = self.long_kids(c, fraction);
            if self.pos[c].distance(self.pos[j]) < FORK_NEAR * self.extent && forks.len() >= 2 {
                out.extend(self.branches(c, fraction));
            } else {
                out.push(c);
            }
        }
        out
    }

    /// The chain from `start` down the child that reaches furthest, to a leaf.
    fn chain(&self, start: usize) -> Vec<usize> {
        let mut out = vec![start];
        let mut cur = start;
        while let Some(&next) = self.kids[cur].iter().max_by(|&&a, &&b| self.through(a).total_cmp(&self.through(b))) {
            out.push(next);
            cur = next;
        }
        out
    }

    /// Path length along `chain` from its `a`-th joint to its `b`-th.
    fn along(&self, chain: &[usize], a: usize, b: usize) -> f64 {
        (a..b).map(|k| self.pos[chain[k + 1]].distance(self.pos[chain[k]])).sum()
    }

    /// The joint of `chain[lo..hi]` nearest `fraction` of the way (by path length) from `chain[from]`
    /// to `chain[to]`.
    fn at_fraction(&self, chain: &[usize], from: usize, to: usize, lo: usize, hi: usize, fraction: f64) -> usize {
        let total = self.along(chain, from, to);
        (lo..hi)
            .min_by(|&a, &b| {
                let da = (self.along(chain, from, a) - fraction * total).abs();
                let db = (self.along(chain, from, b) - fraction * total).abs();
                da.total_cmp(&db)
            })
            .expect("a non-empty range")
    }
}

/// A leg read along its chain: thigh, knee, ankle and toe (when the foot has one).
struct Leg {
    thigh: usize,
    shin: usize,
    foot: usize,
    toe: Option<usize>,
}

struct Arm {
    clavicle: Option<usize>,
    upper: usize,
    fore: usize,
    hand: usize,
}

/// Roles of `s` from its rest pose (or the pose of global joint positions `posed`), or what could
/// not be found.
pub(crate) fn by_shape(s: &Skeleton, posed: Option<&[DVec3]>) -> Result<ShapeRoles, String> {
    let g = Geometry::new(s, posed);
    let order = bfs(&g);
    let hips = *order
        .iter()
        .find(|&&j| g.branches(j, LIMB).len() >= 3)
        .ok_or("no joint has three long branches (two legs and a spine)")?;
    let branches = g.branches(hips, LIMB);
    // The torso is the branch with the most joints (arms, fingers, head); its chest the first joint
    // with two long branches (the arms).
    let size = |b: usize| bfs_from(&g, b).len();
    let torso_branch = *branches.iter().max_by_key(|&&b| (size(b), std::cmp::Reverse(b))).expect("three branches");
    let chest = bfs_from(&g, torso_branch)
        .into_iter()
        .find(|&j| g.long_kids(j, LIMB * 0.8).len() >= 2)
        .ok_or_else(|| format!("the spine from '{}' has no joint two arms branch from", s.joint(torso_branch).name))?;
    let mut legs: Vec<usize> = branches.iter().copied().filter(|&b| b != torso_branch).collect();
    legs.sort_by(|&a, &b| g.through(b).total_cmp(&g.through(a)));
    legs.truncate(2);
    let up = (g.pos[chest] - g.pos[hips]).try_normalize().ok_or("the chest sits at the hips")?;
    let mut arm_roots = g.long_kids(chest, LIMB * 0.8);
    arm_roots.sort_by(|&a, &b| g.through(b).total_cmp(&g.through(a)));
    arm_roots.truncate(2);
    // The neck: of the chest's other branches, the one reaching highest.
    let neck_root = g.kids[chest]
        .iter()
        .copied()
        .filter(|c| !arm_roots.contains(c))
        .filter(|&c| g.through(c) >= 0.05 * g.extent)
        .max_by(|&a, &b| {
            let tip = |c: usize| g.chain(c).last().map(|&t| (g.pos[t] - g.pos[chest]).dot(up)).unwrap_or(0.0);
            tip(a).total_cmp(&tip(b))
        })
        .ok_or("no neck branch above the arms")?;
    let (head, head_conf) = head_of(&g, neck_root);
    let read_legs = [read_leg(&g, hips, legs[0])?, read_leg(&g, hips, legs[1])?];
    for leg in &read_legs {
        let down = (g.pos[leg.foot] - g.pos[leg.thigh]).normalize_or_zero().dot(-up);
        if down < 0.5 {
            return Err(format!(
                "the leg from '{}' does not hang below the hips, away from the spine (cosine {down:.2}): \
                 not a standing humanoid",
                s.joint(leg.thigh).name
            ));
        }
    }
    let axis = (g.pos[hips], up);
    let read_arms = [read_arm(&g, arm_roots[0], axis)?, read_arm(&g, arm_roots[1], axis)?];

    // Forward from the toes (foot to toe, across the up axis); the BVH and glTF convention (+Z)
    // when the feet have none.
    let mut notes = Vec::new();
    let toe_fwd: DVec3 = read_legs.iter().filter_map(|l| l.toe.map(|t| g.pos[t] - g.pos[l.foot])).sum();
    let toe_fwd = toe_fwd - up * toe_fwd.dot(up);
    let (forward, side_conf) = if toe_fwd.length() > SAME_PLACE * g.extent {
        (toe_fwd.normalize(), 1.0)
    } else {
        notes.push("no toes to face by: the character is taken to face +Z".to_string());
        ((DVec3::Z - up * up.z).try_normalize().unwrap_or(DVec3::X), 0.6)
    };
    let left = up.cross(forward);
    let split = |a: DVec3, b: DVec3| -> (bool, f64) {
        let (da, db) = ((a - g.pos[hips]).dot(left), (b - g.pos[hips]).dot(left));
        (da >= db, ((da - db).abs() / (0.05 * g.extent)).min(1.0))
    };
    let (leg0_left, leg_conf) = split(g.pos[read_legs[0].thigh], g.pos[read_legs[1].thigh]);
    let (arm0_left, arm_conf) = split(g.pos[read_arms[0].upper], g.pos[read_arms[1].upper]);

    let mut found = vec![(Role::Hips, hips, 1.0), (Role::Head, head, head_conf)];
    for (k, leg) in read_legs.iter().enumerate() {
        let side = if (k == 0) == leg0_left { Side::Left } else { Side::Right };
        let c = side_conf * leg_conf;
        found.extend([
            (Role::Thigh(side), leg.thigh, c),
            (Role::Shin(side), leg.shin, c),
            (Role::Foot(side), leg.foot, c),
        ]);
        if let Some(t) = leg.toe {
            found.push((Role::Toe(side), t, c));
        }
    }
    for (k, arm) in read_arms.iter().enumerate() {
        let side = if (k == 0) == arm0_left { Side::Left } else { Side::Right };
        let c = side_conf * arm_conf;
        found.extend([
            (Role::UpperArm(side), arm.upper, c),
            (Role::Forearm(side), arm.fore, c),
            (Role::Hand(side), arm.hand, c),
        ]);
        if let Some(cl) = arm.clavicle {
            found.push((Role::Clavicle(side), cl, c));
        }
    }
    Ok(ShapeRoles { found, notes })
}

/// The head on the neck's chain: the first joint past the neck's root that branches (jaw, eyes),
/// else the chain's end when it has an end site, else the joint before a bare end marker
/// (`HeadTop_End`).
fn head_of(g: &Geometry, neck_root: usize) -> (usize, f64) {
    let chain = g.chain(neck_root);
    if let Some(mut k) = (1..chain.len()).find(|&k| g.kids[chain[k]].len() >= 2) {
        // A helper at the head's place that holds the face (`CC_Base_FacialBone`) is not the head.
        while k > 1 && g.pos[chain[k]].distance(g.pos[chain[k - 1]]) < SAME_PLACE * g.extent {
            k -= 1;
        }
        return (chain[k], 0.9);
    }
    let last = *chain.last().expect("a chain holds its start");
    if chain.len() < 2 || g.s.joint(last).end_site.is_some_and(|e| e.length() > 1e-9) {
        (last, 0.9)
    } else {
        (chain[chain.len() - 2], 0.7)
    }
}

fn read_leg(g: &Geometry, hips: usize, start: usize) -> Result<Leg, String> {
    let near = SAME_PLACE * g.extent;
    let chain: Vec<usize> = g.chain(start).into_iter().skip_while(|&j| g.pos[j].distance(g.pos[hips]) < near).collect();
    let name = &g.s.joint(start).name;
    if chain.len() < 3 {
        return Err(format!(
            "the leg from '{name}' has {} joints away from the hips; expected thigh, knee, ankle",
            chain.len()
        ));
    }
    // The foot starts where the chain's next link is short beside the leg above it: lengths, not
    // directions, so a pointed foot in a posed frame reads the same.
    let ankle = (2..chain.len() - 1)
        .find(|&k| g.pos[chain[k + 1]].distance(g.pos[chain[k]]) < FOOT_MAX * g.along(&chain, 0, k))
        .unwrap_or(chain.len() - 1);
    let knee = g.at_fraction(&chain, 0, ankle, 1, ankle, KNEE_AT);
    Ok(Leg { thigh: chain[0], shin: chain[knee], foot: chain[ankle], toe: chain.get(ankle + 1).copied() })
}

fn read_arm(g: &Geometry, start: usize, axis: (DVec3, DVec3)) -> Result<Arm, String> {
    let chain = g.chain(start);
    let name = &g.s.joint(start).name;
    // The hand: the first joint with two comparable branches (fingers and thumb) that are short
    // beside the arm above (an elbow's twist bone beside the forearm is not a finger), else the
    // chain's end.
    let fingers = |k: usize| {
        let j = chain[k];
        let longest = g.kids[j].iter().map(|&c| g.through(c)).fold(0.0, f64::max);
        longest >= SAME_PLACE * g.extent
            && longest < FINGERS_MAX * g.along(&chain, 0, k)
            && g.kids[j].iter().filter(|&&c| g.through(c) >= 0.3 * longest).count() >= 2
    };
    let h = (2..chain.len()).find(|&k| fingers(k)).unwrap_or(chain.len() - 1);
    if h < 2 {
        return Err(format!("the arm from '{name}' has {} joints before its hand; expected upper arm, elbow", h));
    }
    // A clavicle starts near the spine's axis and ends at the shoulder, out to the side.
    let from_axis = |j: usize| {
        let d = g.pos[j] - axis.0;
        (d - axis.1 * d.dot(axis.1)).length()
    };
    // In a posed frame the axis may lean: a link short beside the arm that bends into it (a twist
    // joint continues its bone straight) is a clavicle too.
    let link = |k: usize| g.pos[chain[k + 1]] - g.pos[chain[k]];
    let bends = h >= 3 && link(0).angle_between(link(1)) > CLAVICLE_BEND;
    let short = g.along(&chain, 0, 1) < CLAVICLE_SHORT * g.along(&chain, 1, h);
    let clavicle = h >= 3 && (from_axis(chain[0]) < CLAVICLE_MAX * from_axis(chain[1]) || (short && bends));
    let s = usize::from(clavicle);
    let e = g.at_fraction(&chain, s, h, s + 1, h, ELBOW_AT);
    Ok(Arm { clavicle: clavicle.then_some(chain[0]), upper: chain[s], fore: chain[e], hand: chain[h] })
}

fn bfs(g: &Geometry) -> Vec<usize> {
    bfs_from(g, 0)
}

fn bfs_from(g: &Geometry, start: usize) -> Vec<usize> {
    let mut out = vec![start];
    let mut k = 0;
    while k < out.len() {
        out.extend(g.kids[out[k]].iter().copied());
        k += 1;
    }
    out
}
