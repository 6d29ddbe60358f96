//! Joint hierarchy: names, parents, rest offsets, channel layout and end sites.

use crate::rotation::{Axis, EulerOrder};
use crate::CoreError;
use glam::DVec3;
use serde::{Deserialize, Serialize};

/// One animated degree of freedom of a joint, as in a BVH `CHANNELS` line.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Channel {
    Xposition,
    Yposition,
    Zposition,
    Xrotation,
    Yrotation,
    Zrotation,
}

impl Channel {
    /// Parses a BVH channel name (case-insensitive).
    pub fn parse(s: &str) -> Option<Channel> {
        Some(match s.to_ascii_lowercase().as_str() {
            "xposition" => Channel::Xposition,
            "yposition" => Channel::Yposition,
            "zposition" => Channel::Zposition,
            "xrotation" => Channel::Xrotation,
            "yrotation" => Channel::Yrotation,
            "zrotation" => Channel::Zrotation,
            _ => return None,
        })
    }

    /// BVH spelling.
    pub fn name(self) -> &'static str {
        match self {
            Channel::Xposition => "Xposition",
            Channel::Yposition => "Yposition",
            Channel::Zposition => "Zposition",
            Channel::Xrotation => "Xrotation",
            Channel::Yrotation => "Yrotation",
            Channel::Zrotation => "Zrotation",
        }
    }

    pub fn is_rotation(self) -> bool {
        matches!(self, Channel::Xrotation | Channel::Yrotation | Channel::Zrotation)
    }

    pub fn axis(self) -> Axis {
        match self {
            Channel::Xposition | Channel::Xrotation => Axis::X,
            Channel::Yposition | Channel::Yrotation => Axis::Y,
            Channel::Zposition | Channel::Zrotation => Axis::Z,
        }
    }

    /// The three position channels in x, y, z order.
    pub const POSITION_XYZ: [Channel; 3] = [Channel::Xposition, Channel::Yposition, Channel::Zposition];

    /// The three rotation channels of an Euler order, in that order.
    pub fn rotations(order: EulerOrder) -> [Channel; 3] {
        order.axes().map(|a| match a {
            Axis::X => Channel::Xrotation,
            Axis::Y => Channel::Yrotation,
            Axis::Z => Channel::Zrotation,
        })
    }
}

/// One joint. `offset` is the rest translation from the parent joint (for the root: from the origin).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Joint {
    pub name: String,
    pub parent: Option<usize>,
    pub offset: DVec3,
    pub channels: Vec<Channel>,
    /// Offset of the BVH `End Site` below this joint, if any.
    pub end_site: Option<DVec3>,
}

impl Joint {
    /// Euler order of this joint's rotation channels (ZYX when it has none, the value is unused).
    /// Fails when the channels hold a partial or repeated set of rotation axes that is not all three.
    pub fn rotation_order(&self) -> Option<EulerOrder> {
        let axes: Vec<Axis> = self.channels.iter().filter(|c| c.is_rotation()).map(|c| c.axis()).collect();
        match axes.len() {
            3 => EulerOrder::from_axes([axes[0], axes[1], axes[2]]),
            _ => None,
        }
    }

    pub fn has_translation(&self) -> bool {
        self.channels.iter().any(|c| !c.is_rotation())
    }
}

/// A joint hierarchy in topological order: every parent index is smaller than its child's.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Skeleton {
    joints: Vec<Joint>,
    /// First channel of each joint in a frame vector.
    channel_start: Vec<usize>,
    num_channels: usize,
}

impl Skeleton {
    /// Checks the hierarchy (one root first, parents before children, unique names, finite offsets).
    pub fn new(joints: Vec<Joint>) -> Result<Skeleton, CoreError> {
        if joints.is_empty() {
            return Err(CoreError::InvalidSkeleton("no joints".into()));
        }
        if joints[0].parent.is_some() {
            return Err(CoreError::InvalidSkeleton("the first joint must be the root".into()));
        }
        let mut names = std::collections::HashSet::new();
        for (i, j) in joints.iter().enumerate() {
            if i > 0 {
                match j.parent {
                    Some(p) if p < i => {}
                    Some(p) => {
                        return Err(CoreError::InvalidSkeleton(format!(
                            "joint {i} '{}' has parent {p}, which does not come before it",
                            j.name
                        )))
                    }
                    None => return Err(CoreError::InvalidSkeleton(format!("joint {i} '{}' is a second root", j.name))),
                }
            }
            if !names.insert(j.name.as_str()) {
                return Err(CoreError::InvalidSkeleton(format!("joint name '{}' appears twice", j.name)));
            }
            let finite = j.offset.is_finite() && j.end_site.is_none_or(|e| e.is_finite());
            if !finite {
                return Err(CoreError::InvalidSkeleton(format!("joint '{}' has a non-finite offset", j.name)));
            }
            let rot = j.channels.iter().filter(|c| c.is_rotation()).count();
            if rot != 0 && j.rotation_order().is_none() {
                return Err(CoreError::InvalidSkeleton(format!(
                    "joint '{}' has rotation channels {:?}; expected none or one each of X, Y, Z",
                    j.name, j.channels
                )));
            }
        }
        let mut channel_start = Vec::with_capacity(joints.len());
        let mut n = 0;
        for j in &joints {
            channel_start.push(n);
            n += j.channels.len();
        }
        Ok(Skeleton { joints, channel_start, num_channels: n })
    }

    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    pub fn joint(&self, i: usize) -> &Joint {
        &self.joints[i]
    }

    pub fn len(&self) -> usize {
        self.joints.len()
    }

    pub fn is_empty(&self) -> bool {
        self.joints.is_empty()
    }

    pub fn num_channels(&self) -> usize {
        self.num_channels
    }

    /// Index of joint `i`'s first channel in a frame vector.
    pub fn channel_start(&self, i: usize) -> usize {
        self.channel_start[i]
    }

    pub fn find(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    pub fn parent(&self, i: usize) -> Option<usize> {
        self.joints[i].parent
    }

    pub fn children(&self, i: usize) -> impl Iterator<Item = usize> + '_ {
        self.joints.iter().enumerate().filter(move |(_, j)| j.parent == Some(i)).map(|(c, _)| c)
    }

    /// Length of the bone from each joint's parent to the joint (0 for the root).
    pub fn bone_lengths(&self) -> Vec<f64> {
        self.joints.iter().map(|j| if j.parent.is_some() { j.offset.length() } else { 0.0 }).collect()
    }

    /// Keeps the joints for which `keep` is true; dropping a joint drops its whole subtree (fingers,
    /// toes), so the kept joints move exactly as before. The root always stays.
    ///
    /// Returns the new skeleton and, for each new joint, its index in `self`.
    pub fn filter(&self, keep: impl Fn(usize, &Joint) -> bool) -> (Skeleton, Vec<usize>) {
        let mut new_index: Vec<Option<usize>> = vec![None; self.len()];
        let mut joints = Vec::new();
        let mut source = Vec::new();
        for (i, j) in self.joints.iter().enumerate() {
            let parent_new = match j.parent {
                None => None,
                Some(p) => match new_index[p] {
                    Some(np) => Some(np),
                    None => continue,
                },
            };
            if i != 0 && !keep(i, j) {
                continue;
            }
            new_index[i] = Some(joints.len());
            source.push(i);
            joints.push(Joint { parent: parent_new, ..j.clone() });
        }
        (Skeleton::new(joints).expect("filtering keeps a valid hierarchy"), source)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn joint(name: &str, parent: Option<usize>, offset: DVec3) -> Joint {
        Joint {
            name: name.into(),
            parent,
            offset,
            channels: Channel::rotations(EulerOrder::Zyx).to_vec(),
            end_site: None,
        }
    }

    #[test]
    fn rejects_bad_hierarchies() {
        assert!(Skeleton::new(vec![]).is_err());
        let two_roots = vec![joint("a", None, DVec3::ZERO), joint("b", None, DVec3::X)];
        assert!(Skeleton::new(two_roots).is_err());
        let dup = vec![joint("a", None, DVec3::ZERO), joint("a", Some(0), DVec3::X)];
        assert!(Skeleton::new(dup).is_err());
        let mut partial = joint("a", None, DVec3::ZERO);
        partial.channels = vec![Channel::Xrotation, Channel::Xrotation, Channel::Yrotation];
        assert!(Skeleton::new(vec![partial]).is_err());
    }

    #[test]
    fn filter_drops_whole_subtrees() {
        let s = Skeleton::new(vec![
            joint("root", None, DVec3::ZERO),
            joint("mid", Some(0), DVec3::new(0.0, 1.0, 0.0)),
            joint("tip", Some(1), DVec3::new(0.0, 2.0, 0.0)),
        ])
        .unwrap();
        let (f, src) = s.filter(|_, j| j.name != "mid");
        assert_eq!(src, vec![0]);
        assert_eq!(f.len(), 1);
        let (f, src) = s.filter(|_, j| j.name != "tip");
        assert_eq!(src, vec![0, 1]);
        assert_eq!(f.joint(1).parent, Some(0));
        assert_eq!(f.num_channels(), 6);
    }
}
