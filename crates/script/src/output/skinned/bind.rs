//! Binding a Kenney blocky character to the rig: each part placed on its rig segment, cut at the
//! rig's joints and bound rigidly (see the parent module's doc).

use super::*;
use inbetween_core::roles::{find_roles, Role, RoleOverrides, Side};

/// How one part is placed: Kenney segment `from → from + axis_k · len_k` onto the rig segment
/// `to → to + axis_r · len_r`, scaled by `width` across it; then cut into spans along the rig
/// segment, span k starting `cuts[k].0` metres from `to` and bound to joint `cuts[k].1`.
#[derive(Clone)]
struct Placement {
    from: Vec3,
    axis_k: Vec3,
    len_k: f32,
    to: Vec3,
    axis_r: Vec3,
    len_r: f32,
    width: f32,
    cuts: Vec<(f32, usize)>,
}

impl Placement {
    fn rotation(&self) -> Quat {
        Quat::from_rotation_arc(self.axis_k, self.axis_r)
    }

    /// A Kenney point into bind space.
    fn point(&self, q: Vec3) -> Vec3 {
        let d = q - self.from;
        let a = d.dot(self.axis_k);
        let scaled = self.axis_k * a * (self.len_r / self.len_k) + (d - self.axis_k * a) * self.width;
        self.to + self.rotation() * scaled
    }

    /// A Kenney normal into bind space (inverse transpose of the scale).
    fn normal(&self, n: Vec3) -> Vec3 {
        let a = n.dot(self.axis_k);
        let scaled = self.axis_k * a / (self.len_r / self.len_k) + (n - self.axis_k * a) / self.width;
        (self.rotation() * scaled).normalize_or_zero()
    }

    /// Distance along the rig segment of a bind-space point.
    fn along(&self, p: Vec3) -> f32 {
        (p - self.to).dot(self.axis_r)
    }
}

/// Top and bottom centres of a part's bounding box.
fn top_bottom(part: &KenneyPart) -> (Vec3, Vec3) {
    let (lo, hi) = part.positions.iter().fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), p| {
        (lo.min(Vec3::from(*p)), hi.max(Vec3::from(*p)))
    });
    let c = (lo + hi) / 2.0;
    (Vec3::new(c.x, hi.y, c.z), Vec3::new(c.x, lo.y, c.z))
}

fn segment(a: Vec3, b: Vec3) -> (Vec3, f32) {
    let d = b - a;
    (d.normalize_or(Vec3::NEG_Y), d.length().max(1e-4))
}

/// The farthest joint or end site below `j` (inclusive) from point `from`.
fn farthest_below(skeleton: &Skeleton, g: &GlobalPose, j: usize, from: DVec3) -> DVec3 {
    let mut best = g.positions[j];
    let mut stack = vec![j];
    while let Some(k) = stack.pop() {
        for p in std::iter::once(g.positions[k]).chain(g.end_site(skeleton, k)) {
            if p.distance(from) > best.distance(from) {
                best = p;
            }
        }
        stack.extend(skeleton.children(k));
    }
    best
}

/// Vertices of one piece under construction, merged when identical.
#[derive(Default)]
struct Builder {
    body_pos: Vec<Vec3>,
    body_nor: Vec<Vec3>,
    body_uv: Vec<[f32; 2]>,
    body_joint: Vec<u16>,
    indices: Vec<u32>,
    seen: HashMap<VertexKey, u32>,
}

/// Bit patterns of position, normal and uv, and the joint: identical vertices merge.
type VertexKey = ([u32; 3], [u32; 3], [u32; 2], u16);

/// A clipped vertex: position, normal, uv.
type V = (Vec3, Vec3, [f32; 2]);

fn lerp_v(a: &V, b: &V, t: f32) -> V {
    (a.0.lerp(b.0, t), a.1.lerp(b.1, t), [a.2[0] + (b.2[0] - a.2[0]) * t, a.2[1] + (b.2[1] - a.2[1]) * t])
}

/// Sutherland–Hodgman: the part of polygon `poly` where `f(p) ≥ 0` (`> 0` when `strict`, so a face
/// lying on a cut plane goes to one side only); `f` is affine in p.
fn clip(poly: &[V], f: impl Fn(Vec3) -> f32, strict: bool) -> Vec<V> {
    let inside = |x: f32| if strict { x > 0.0 } else { x >= 0.0 };
    let mut out = Vec::new();
    for i in 0..poly.len() {
        let (a, b) = (&poly[i], &poly[(i + 1) % poly.len()]);
        let (fa, fb) = (f(a.0), f(b.0));
        if inside(fa) {
            out.push(*a);
        }
        if inside(fa) != inside(fb) && fa != fb {
            out.push(lerp_v(a, b, fa / (fa - fb)));
        }
    }
    out
}

impl Builder {
    fn vertex(&mut self, v: &V, joint: u16) -> u32 {
        let n = v.1.normalize_or_zero();
        let key = (v.0.to_array().map(f32::to_bits), n.to_array().map(f32::to_bits), v.2.map(f32::to_bits), joint);
        if let Some(&i) = self.seen.get(&key) {
            return i;
        }
        let i = self.body_pos.len() as u32;
        self.body_pos.push(v.0);
        self.body_nor.push(n);
        self.body_uv.push(v.2);
        self.body_joint.push(joint);
        self.seen.insert(key, i);
        i
    }

    /// Adds a part placed by `pl`, each triangle clipped into the spans of `pl.cuts`.
    fn add(&mut self, part: &KenneyPart, pl: &Placement) {
        let verts: Vec<V> = (0..part.positions.len())
            .map(|i| (pl.point(Vec3::from(part.positions[i])), pl.normal(Vec3::from(part.normals[i])), part.uvs[i]))
            .collect();
        for tri in part.indices.chunks_exact(3) {
            let poly: Vec<V> = tri.iter().map(|&i| verts[i as usize]).collect();
            for (k, &(start, joint)) in pl.cuts.iter().enumerate() {
                let mut piece = poly.clone();
                if k > 0 {
                    piece = clip(&piece, |p| pl.along(p) - start, false);
                }
                if let Some(&(end, _)) = pl.cuts.get(k + 1) {
                    piece = clip(&piece, |p| end - pl.along(p), true);
                }
                if piece.len() < 3 {
                    continue;
                }
                let ids: Vec<u32> = piece.iter().map(|v| self.vertex(v, joint as u16)).collect();
                for w in 1..ids.len() - 1 {
                    let (a, b, c) = (ids[0], ids[w], ids[w + 1]);
                    let (pa, pb, pc) =
                        (self.body_pos[a as usize], self.body_pos[b as usize], self.body_pos[c as usize]);
                    if (pb - pa).cross(pc - pa).length_squared() > 1e-14 {
                        self.indices.extend([a, b, c]);
                    }
                }
            }
        }
    }
}

/// Retargets a Kenney character onto `skeleton` (any humanoid: its joints found by their roles,
/// [`inbetween_core::roles`]) in its bind pose (see the module comment). Needs a "torso" part;
/// legs, arms and head are placed when present, any other part rides on the torso.
pub fn bind_body(ch: &KenneyCharacter, skeleton: &Skeleton) -> Result<SkinnedBody, ScriptError> {
    let roles = find_roles(skeleton, &RoleOverrides::default())
        .map_err(|e| ScriptError::Invalid(format!("skinning needs a humanoid skeleton: {e}")))?;
    let (l, r) = (Side::Left, Side::Right);
    let j = |role: Role| roles.joint(role);
    let (head, lul, ll, lf, rul, rl, rf) = (
        j(Role::Head),
        j(Role::Thigh(l)),
        j(Role::Shin(l)),
        j(Role::Foot(l)),
        j(Role::Thigh(r)),
        j(Role::Shin(r)),
        j(Role::Foot(r)),
    );
    let (la, lfa, lh, ra, rfa, rh) = (
        j(Role::UpperArm(l)),
        j(Role::Forearm(l)),
        j(Role::Hand(l)),
        j(Role::UpperArm(r)),
        j(Role::Forearm(r)),
        j(Role::Hand(r)),
    );
    // The spine from its lowest joint up to the chest (`LowerBack`, `Spine`, `Spine1`).
    let (lower_back, spine1) = match (roles.spine.first(), roles.spine.last()) {
        (Some(&a), Some(&b)) => (a, b),
        _ => return Err(ScriptError::Invalid("skinning needs a spine joint between the hips and the arms".into())),
    };
    let middle: Vec<usize> = roles.spine.iter().copied().skip(1).take(roles.spine.len().saturating_sub(2)).collect();
    let (_, g) = bind_pose(skeleton);
    let p = |j: usize| g.positions[j].as_vec3();
    let bad = |m: String| ScriptError::Asset { path: ch.source.clone(), message: m };
    let torso = ch.part("torso").ok_or_else(|| bad("no 'torso' part: not a Kenney blocky character".into()))?;

    // One width scale: the rig's shoulder half-span over the Kenney arm's centre offset.
    let (kt_top, kt_bot) = top_bottom(torso);
    let shoulder_half = (p(la) - p(ra)).length() / 2.0;
    let arm_centre =
        ch.part("arm-left").or(ch.part("arm-right")).map(|a| (top_bottom(a).0 - kt_top).with_y(0.0).length());
    let torso_half = torso.positions.iter().map(|q| (q[0] - kt_top.x).abs()).fold(0.0f32, f32::max);
    let width = shoulder_half / arm_centre.filter(|c| *c > 1e-3).unwrap_or(torso_half.max(1e-3) * 1.5);

    let hip_mid = (p(lul) + p(rul)) / 2.0;
    let shoulder_mid = (p(la) + p(ra)) / 2.0;
    let (torso_axis, torso_len) = segment(hip_mid, shoulder_mid);
    let (kt_axis, kt_len) = segment(kt_bot, kt_top);
    let mut torso_cuts = vec![(f32::MIN, lower_back)];
    for &s in &middle {
        torso_cuts.push(((p(s) - hip_mid).dot(torso_axis), s));
    }
    if spine1 != lower_back {
        torso_cuts.push(((p(spine1) - hip_mid).dot(torso_axis), spine1));
    }
    let torso_pl = Placement {
        from: kt_bot,
        axis_k: kt_axis,
        len_k: kt_len,
        to: hip_mid,
        axis_r: torso_axis,
        len_r: torso_len,
        width,
        cuts: torso_cuts,
    };

    let mut b = Builder::default();
    for part in &ch.parts {
        let (top, bot) = top_bottom(part);
        let pl = match part.name.as_str() {
            "leg-left" | "leg-right" => {
                let (up, knee, ankle) = if part.name == "leg-left" { (lul, ll, lf) } else { (rul, rl, rf) };
                // Across: where the Kenney proportions put it under the torso; along: hip joint to floor.
                let at = torso_pl.point(Vec3::new(top.x, kt_bot.y, top.z));
                let to = Vec3::new(at.x, p(up).y, at.z);
                let (axis_k, len_k) = segment(top, bot);
                let along = |jj: usize| p(up).y - p(jj).y;
                Placement {
                    from: top,
                    axis_k,
                    len_k,
                    to,
                    axis_r: Vec3::NEG_Y,
                    len_r: to.y,
                    width,
                    cuts: vec![(f32::MIN, up), (along(knee), knee), (along(ankle), ankle)],
                }
            }
            "arm-left" | "arm-right" => {
                let (arm, elbow, wrist) = if part.name == "arm-left" { (la, lfa, lh) } else { (ra, rfa, rh) };
                let tip = farthest_below(skeleton, &g, wrist, g.positions[arm]).as_vec3();
                let (axis_r, len_r) = segment(p(arm), tip);
                let (axis_k, len_k) = segment(top, bot);
                let along = |jj: usize| (p(jj) - p(arm)).dot(axis_r);
                Placement {
                    from: top,
                    axis_k,
                    len_k,
                    to: p(arm),
                    axis_r,
                    len_r,
                    width,
                    cuts: vec![(f32::MIN, arm), (along(elbow), elbow), (along(wrist), wrist)],
                }
            }
            "head" => {
                let (axis_k, len_k) = segment(bot, top);
                let to = torso_pl.to + torso_pl.axis_r * torso_pl.len_r;
                Placement {
                    from: bot,
                    axis_k,
                    len_k,
                    to,
                    axis_r: Vec3::Y,
                    len_r: len_k * width,
                    width,
                    cuts: vec![(f32::MIN, head)],
                }
            }
            // Anything else rides on the torso, on the head above the shoulders.
            _ => Placement { cuts: [torso_pl.cuts.clone(), vec![(torso_len, head)]].concat(), ..torso_pl.clone() },
        };
        b.add(part, &pl);
    }
    Ok(SkinnedBody {
        positions: b.body_pos,
        normals: b.body_nor,
        uvs: b.body_uv,
        joints: b.body_joint,
        indices: b.indices,
        bind: joint_matrices(&g),
        image: ch.image.clone(),
        base_color: ch.base_color,
        source: ch.source.clone(),
    })
}
