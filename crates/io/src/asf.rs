//! ASF/AMC (Acclaim skeleton + motion capture) reader, converted to a BVH-style [`Motion`].
//!
//! # Conversion
//! * One BVH joint per ASF bone, plus the root (named `root`), in depth-first order of `:hierarchy`.
//!   A joint sits at the **start** of its bone, so a joint's offset is its PARENT bone's
//!   `direction × length` (zero below the root, which has no length); leaf bones get an End Site at
//!   their tip. This is what the CMU→BVH converters do (cgspeed's `LHipJoint` has offset 0 and
//!   `LeftUpLeg` carries the `lhipjoint` bone vector).
//! * Each bone has an axis frame `C` (from `axis a b c ORDER`, in global rest coordinates). Its
//!   rotation relative to the parent is `L = C · M · C⁻¹`, where `M` composes the AMC values in dof
//!   order, the first listed dof applied first: `dof rx ry rz` gives `M = Rz · Ry · Rx`. `C` is built
//!   the same way from the axis angles in the axis order. Global rotations are products of `L` along
//!   the chain, as in the CMU viewer. `L` is written as `Zrotation Yrotation Xrotation` channels
//!   ([`EulerOrder::from_quat`]), every bone gets those three channels (a bone without dof has zero
//!   values), and the root gets `Xposition Yposition Zposition` first: the cgspeed layout.
//! * Root: `order TX TY TZ RX RY RZ` says which AMC value is which; `position` is the root's rest
//!   offset and `orientation`/`axis` its `C`.
//!
//! # Units
//! Lengths are kept exactly as written in the files (the ASF `:units length` value is recorded but not
//! applied). CMU files say `length 0.45`, meaning one file unit is 1/0.45 inch = 5.6444 cm; the AMC
//! root translations are in the same unit, and the cgspeed BVH conversions use it too (the cgspeed
//! `01_01.bvh` root position 9.3722 17.8693 -17.3198 equals the AMC's 9.37216 17.8693 -17.3198, and
//! its `LeftUpLeg` offset 1.36306 -1.79463 0.83929 equals `lhipjoint` direction × length 2.40479), so
//! both encodings compare directly. Angles honour `:units angle deg|rad` and the AMC `:DEGREES` /
//! `:RADIANS` header (the header wins); output channels are degrees as everywhere in [`Motion`].

use crate::{read_text, IoError};
use glam::{DQuat, DVec3};
use inbetween_core::{Axis, Channel, EulerOrder, Joint, Motion, Skeleton};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

/// The Euler order of every converted rotation channel.
pub const OUTPUT_ORDER: EulerOrder = EulerOrder::Zyx;

/// Frame time written for AMC data, which does not store its rate: CMU captured at 120 fps.
pub const AMC_FRAME_TIME: f64 = 1.0 / 120.0;

/// Reads an ASF skeleton file and an AMC motion file.
pub fn read_asf_amc(asf: &Path, amc: &Path) -> Result<Motion, IoError> {
    let asf_text = read_text(asf)?;
    let amc_text = read_text(amc)?;
    parse_asf_amc(&asf_text, &amc_text, &asf.display().to_string(), &amc.display().to_string())
}

/// Parses an ASF skeleton and an AMC motion into a BVH-style [`Motion`] at 120 fps (see the module
/// documentation for the conversion).
pub fn parse_asf_amc(asf_text: &str, amc_text: &str, asf_name: &str, amc_name: &str) -> Result<Motion, IoError> {
    let asf = parse_asf(asf_text, asf_name)?;
    let skeleton = asf.to_skeleton().map_err(|m| invalid(asf_name, 1, m))?;
    let data = parse_amc(&asf, amc_text, amc_name)?;
    Motion::new(skeleton, AMC_FRAME_TIME, data).map_err(|e| invalid(amc_name, 1, e.to_string()))
}

/// The skeleton file for an AMC file: CMU naming (`01_01.amc` → `01.asf`) or the same stem.
pub fn find_asf_for(amc: &Path) -> Result<PathBuf, IoError> {
    let dir = amc.parent().unwrap_or(Path::new(""));
    let stem = amc.file_stem().and_then(|s| s.to_str()).unwrap_or("");
    let mut tried = Vec::new();
    if let Some((subject, _)) = stem.split_once('_') {
        tried.push(dir.join(format!("{subject}.asf")));
    }
    tried.push(dir.join(format!("{stem}.asf")));
    match tried.iter().find(|p| p.is_file()) {
        Some(p) => Ok(p.clone()),
        None => Err(IoError::MissingAsf { amc: amc.to_path_buf(), tried }),
    }
}

fn syntax(file: &str, line: usize, expected: impl Into<String>, found: String) -> IoError {
    IoError::Syntax { file: file.to_string(), line, expected: expected.into(), found }
}

fn invalid(file: &str, line: usize, message: impl Into<String>) -> IoError {
    IoError::Invalid { file: file.to_string(), line, message: message.into() }
}

/// One animated degree of freedom of a bone or the root.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Dof {
    Rotate(Axis),
    /// Root translation along an axis (bones may not translate here).
    Translate(Axis),
}

fn parse_dof(word: &str) -> Option<Dof> {
    Some(match word.to_ascii_lowercase().as_str() {
        "rx" => Dof::Rotate(Axis::X),
        "ry" => Dof::Rotate(Axis::Y),
        "rz" => Dof::Rotate(Axis::Z),
        "tx" => Dof::Translate(Axis::X),
        "ty" => Dof::Translate(Axis::Y),
        "tz" => Dof::Translate(Axis::Z),
        _ => return None,
    })
}

/// Rotation applying `angles[0]` about `axes[0]` first, then the next: `R = R_n ⋯ R_1 · R_0`.
fn compose_applied_in_order(axes: &[Axis], angles_rad: &[f64]) -> DQuat {
    axes.iter().zip(angles_rad).fold(DQuat::IDENTITY, |acc, (a, &v)| a.rotation(v) * acc)
}

#[derive(Debug)]
struct Bone {
    name: String,
    line: usize,
    direction: DVec3,
    length: f64,
    axis_angles: [f64; 3],
    axis_order: [Axis; 3],
    dofs: Vec<Axis>,
    #[allow(dead_code)] // parsed for completeness and validation; the motion itself is not clamped
    limits: Vec<(f64, f64)>,
}

impl Bone {
    fn vector(&self) -> DVec3 {
        self.direction * self.length
    }
}

/// A parsed ASF file. Node 0 is the root; node `i > 0` is `bones[i - 1]`.
#[derive(Debug)]
struct Asf {
    /// Multiplies file angles to radians.
    angle_to_rad: f64,
    /// `:units length` as written (recorded, not applied: see the module docs).
    #[allow(dead_code)]
    length_unit: f64,
    root_order: Vec<Dof>,
    root_axis: [Axis; 3],
    root_position: DVec3,
    root_orientation: [f64; 3],
    bones: Vec<Bone>,
    /// Children of each node, in `:hierarchy` order.
    children: Vec<Vec<usize>>,
    /// Nodes in depth-first order: the joint order of the converted skeleton.
    order: Vec<usize>,
}

impl Asf {
    fn axis_frame(&self, node: usize) -> DQuat {
        let (axes, angles) = if node == 0 {
            (self.root_axis, self.root_orientation)
        } else {
            let b = &self.bones[node - 1];
            (b.axis_order, b.axis_angles)
        };
        compose_applied_in_order(&axes, &angles.map(|a| a * self.angle_to_rad))
    }

    fn name(&self, node: usize) -> &str {
        if node == 0 {
            "root"
        } else {
            &self.bones[node - 1].name
        }
    }

    fn to_skeleton(&self) -> Result<Skeleton, String> {
        let mut index_of = vec![usize::MAX; self.bones.len() + 1];
        let mut joints = Vec::with_capacity(self.order.len());
        let mut parent_of = vec![None; self.bones.len() + 1];
        for (p, kids) in self.children.iter().enumerate() {
            for &k in kids {
                parent_of[k] = Some(p);
            }
        }
        for &node in &self.order {
            index_of[node] = joints.len();
            let rot = Channel::rotations(OUTPUT_ORDER).to_vec();
            let (offset, channels) = match parent_of[node] {
                None => (self.root_position, [Channel::POSITION_XYZ.to_vec(), rot].concat()),
                Some(0) => (DVec3::ZERO, rot),
                Some(p) => (self.bones[p - 1].vector(), rot),
            };
            let end_site = (node != 0 && self.children[node].is_empty()).then(|| self.bones[node - 1].vector());
            joints.push(Joint {
                name: self.name(node).to_string(),
                parent: parent_of[node].map(|p| index_of[p]),
                offset,
                channels,
                end_site,
            });
        }
        Skeleton::new(joints).map_err(|e| e.to_string())
    }
}

/// Lines of `text` with 1-based numbers, `\r` and `#` comments removed.
fn clean_lines(text: &str) -> impl Iterator<Item = (usize, &str)> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    text.split('\n').enumerate().map(|(i, l)| {
        let l = l.split('#').next().unwrap_or("");
        (i + 1, l.trim_end_matches('\r'))
    })
}

struct LineParser<'a> {
    file: &'a str,
    line: usize,
}

impl LineParser<'_> {
    fn number(&self, word: Option<&str>, what: &str) -> Result<f64, IoError> {
        let w = word.ok_or_else(|| syntax(self.file, self.line, what, "end of line".into()))?;
        crate::lexer::parse_finite(w).ok_or_else(|| syntax(self.file, self.line, what, crate::lexer::quote(w)))
    }

    fn vec3<'w>(&self, words: &mut impl Iterator<Item = &'w str>, what: &str) -> Result<[f64; 3], IoError> {
        Ok([
            self.number(words.next(), &format!("{what} x (a finite number)"))?,
            self.number(words.next(), &format!("{what} y (a finite number)"))?,
            self.number(words.next(), &format!("{what} z (a finite number)"))?,
        ])
    }

    fn axis_order(&self, word: Option<&str>) -> Result<[Axis; 3], IoError> {
        let w = word.ok_or_else(|| syntax(self.file, self.line, "an axis order such as XYZ", "end of line".into()))?;
        EulerOrder::parse(w)
            .map(|o| o.axes())
            .ok_or_else(|| syntax(self.file, self.line, "an axis order such as XYZ", crate::lexer::quote(w)))
    }
}

#[derive(Clone, Copy, PartialEq)]
enum Section {
    Other,
    Units,
    Root,
    BoneData,
    Hierarchy,
}

fn parse_asf(text: &str, file: &str) -> Result<Asf, IoError> {
    let mut asf = Asf {
        angle_to_rad: 1f64.to_radians(),
        length_unit: 1.0,
        root_order: Vec::new(),
        root_axis: [Axis::X, Axis::Y, Axis::Z],
        root_position: DVec3::ZERO,
        root_orientation: [0.0; 3],
        bones: Vec::new(),
        children: Vec::new(),
        order: Vec::new(),
    };
    let mut section = Section::Other;
    let mut bone: Option<Bone> = None;
    let mut in_limits = false;
    let mut hierarchy: Vec<(usize, Vec<&str>)> = Vec::new();
    let mut saw_root = false;
    for (line, text) in clean_lines(text) {
        let lp = LineParser { file, line };
        let mut words = text.split_ascii_whitespace();
        let Some(first) = words.next() else { continue };
        if first.starts_with(':') {
            if bone.is_some() {
                return Err(syntax(file, line, "'end' closing the bone", crate::lexer::quote(first)));
            }
            in_limits = false;
            section = match first.to_ascii_lowercase().as_str() {
                ":units" => Section::Units,
                ":root" => {
                    saw_root = true;
                    Section::Root
                }
                ":bonedata" => Section::BoneData,
                ":hierarchy" => Section::Hierarchy,
                _ => Section::Other,
            };
            continue;
        }
        let key = first.to_ascii_lowercase();
        match section {
            Section::Other => {}
            Section::Units => match key.as_str() {
                "length" => asf.length_unit = lp.number(words.next(), "a length unit")?,
                "angle" => {
                    asf.angle_to_rad = match words.next().map(|w| w.to_ascii_lowercase()).as_deref() {
                        Some("deg") | Some("degrees") => 1f64.to_radians(),
                        Some("rad") | Some("radians") => 1.0,
                        other => return Err(syntax(file, line, "'deg' or 'rad'", format!("{other:?}"))),
                    }
                }
                _ => {}
            },
            Section::Root => match key.as_str() {
                "order" => {
                    asf.root_order.clear();
                    for w in words {
                        let d = parse_dof(w)
                            .ok_or_else(|| syntax(file, line, "root dof TX TY TZ RX RY RZ", crate::lexer::quote(w)))?;
                        if asf.root_order.contains(&d) {
                            return Err(invalid(file, line, format!("root dof {w} appears twice")));
                        }
                        asf.root_order.push(d);
                    }
                }
                "axis" => asf.root_axis = lp.axis_order(words.next())?,
                "position" => asf.root_position = DVec3::from(lp.vec3(&mut words, "root position")?),
                "orientation" => asf.root_orientation = lp.vec3(&mut words, "root orientation")?,
                _ => {}
            },
            Section::BoneData => {
                if key == "begin" {
                    if bone.is_some() {
                        return Err(syntax(file, line, "'end' closing the bone", "'begin'".into()));
                    }
                    bone = Some(Bone {
                        name: String::new(),
                        line,
                        direction: DVec3::ZERO,
                        length: 0.0,
                        axis_angles: [0.0; 3],
                        axis_order: [Axis::X, Axis::Y, Axis::Z],
                        dofs: Vec::new(),
                        limits: Vec::new(),
                    });
                    in_limits = false;
                    continue;
                }
                let Some(b) = bone.as_mut() else {
                    return Err(syntax(file, line, "'begin' starting a bone", crate::lexer::quote(first)));
                };
                if key.starts_with('(') && in_limits {
                    parse_limits(&lp, std::iter::once(first).chain(words), &mut b.limits)?;
                    continue;
                }
                in_limits = false;
                match key.as_str() {
                    "end" => {
                        let b = bone.take().expect("inside a bone");
                        finish_bone(&b, file, &asf.bones)?;
                        asf.bones.push(b);
                    }
                    "name" => {
                        b.name = words
                            .next()
                            .ok_or_else(|| syntax(file, line, "a bone name", "end of line".into()))?
                            .to_string()
                    }
                    "direction" => b.direction = DVec3::from(lp.vec3(&mut words, "direction")?),
                    "length" => b.length = lp.number(words.next(), "a bone length")?,
                    "axis" => {
                        b.axis_angles = lp.vec3(&mut words, "axis")?;
                        b.axis_order = lp.axis_order(words.next())?;
                    }
                    "dof" => {
                        for w in words {
                            match parse_dof(w) {
                                Some(Dof::Rotate(a)) if !b.dofs.contains(&a) => b.dofs.push(a),
                                Some(Dof::Rotate(_)) => {
                                    return Err(invalid(file, line, format!("dof {w} appears twice")))
                                }
                                _ => {
                                    return Err(syntax(
                                        file,
                                        line,
                                        "bone dof rx, ry or rz (translation and length dof are not supported)",
                                        crate::lexer::quote(w),
                                    ))
                                }
                            }
                        }
                    }
                    "limits" => {
                        in_limits = true;
                        parse_limits(&lp, words, &mut b.limits)?;
                    }
                    _ => {} // id, bodymass, cofmass: not needed for motion
                }
            }
            Section::Hierarchy => {
                if key == "begin" || key == "end" {
                    continue;
                }
                hierarchy.push((line, std::iter::once(first).chain(words).collect()));
            }
        }
    }
    if let Some(b) = bone {
        return Err(syntax(file, b.line, "'end' closing the bone", "end of file".into()));
    }
    if !saw_root {
        return Err(syntax(file, 1, "a ':root' section", "end of file".into()));
    }
    if asf.root_order.is_empty() {
        asf.root_order = vec![
            Dof::Translate(Axis::X),
            Dof::Translate(Axis::Y),
            Dof::Translate(Axis::Z),
            Dof::Rotate(Axis::X),
            Dof::Rotate(Axis::Y),
            Dof::Rotate(Axis::Z),
        ];
    }
    let rot = asf.root_order.iter().filter(|d| matches!(d, Dof::Rotate(_))).count();
    if rot != 0 && rot != 3 {
        return Err(invalid(file, 1, "root order must rotate about none or all of X, Y, Z"));
    }
    build_hierarchy(&mut asf, &hierarchy, file)?;
    Ok(asf)
}

fn parse_limits<'w>(
    lp: &LineParser,
    words: impl Iterator<Item = &'w str>,
    out: &mut Vec<(f64, f64)>,
) -> Result<(), IoError> {
    let mut pending: Option<f64> = None;
    for w in words {
        let w = w.trim_matches(|c| c == '(' || c == ')');
        if w.is_empty() {
            continue;
        }
        // Limits may be infinite ("(-inf inf)"), unlike every other value.
        let v: f64 = w
            .parse()
            .ok()
            .filter(|v: &f64| !v.is_nan())
            .ok_or_else(|| syntax(lp.file, lp.line, "a limit (a number)", crate::lexer::quote(w)))?;
        match pending.take() {
            None => pending = Some(v),
            Some(lo) => out.push((lo, v)),
        }
    }
    if pending.is_some() {
        return Err(syntax(lp.file, lp.line, "limits as (min max) pairs", "an unpaired value".into()));
    }
    Ok(())
}

fn finish_bone(b: &Bone, file: &str, earlier: &[Bone]) -> Result<(), IoError> {
    if b.name.is_empty() {
        return Err(syntax(file, b.line, "a 'name' line in the bone", "none".into()));
    }
    if b.name.eq_ignore_ascii_case("root") || earlier.iter().any(|e| e.name == b.name) {
        return Err(invalid(file, b.line, format!("bone name '{}' is used twice", b.name)));
    }
    if !b.limits.is_empty() && b.limits.len() != b.dofs.len() {
        return Err(invalid(
            file,
            b.line,
            format!("bone '{}' has {} dof but {} limits", b.name, b.dofs.len(), b.limits.len()),
        ));
    }
    Ok(())
}

/// Links `:hierarchy` lines into children lists and a depth-first order; every bone must be
/// reachable from the root exactly once.
fn build_hierarchy(asf: &mut Asf, lines: &[(usize, Vec<&str>)], file: &str) -> Result<(), IoError> {
    let n = asf.bones.len() + 1;
    let mut node_of: HashMap<&str, usize> = HashMap::with_capacity(n);
    node_of.insert("root", 0);
    for (i, b) in asf.bones.iter().enumerate() {
        node_of.insert(b.name.as_str(), i + 1);
    }
    let mut children = vec![Vec::new(); n];
    let mut has_parent = vec![false; n];
    for (line, words) in lines {
        let lookup = |w: &str| {
            node_of
                .get(w)
                .copied()
                .ok_or_else(|| syntax(file, *line, "a bone named in :bonedata", crate::lexer::quote(w)))
        };
        let parent = lookup(words[0])?;
        for &w in &words[1..] {
            let c = lookup(w)?;
            if c == 0 || has_parent[c] {
                return Err(invalid(file, *line, format!("'{w}' already has a parent")));
            }
            has_parent[c] = true;
            children[parent].push(c);
        }
    }
    let mut order = Vec::with_capacity(n);
    let mut stack = vec![0];
    while let Some(node) = stack.pop() {
        order.push(node);
        stack.extend(children[node].iter().rev());
    }
    if order.len() != n {
        let mut reached = vec![false; n];
        order.iter().for_each(|&i| reached[i] = true);
        let missing = (1..n).find(|&i| !reached[i]).unwrap_or(1);
        return Err(invalid(
            file,
            asf.bones[missing - 1].line,
            format!("bone '{}' is not connected to the root in :hierarchy", asf.bones[missing - 1].name),
        ));
    }
    asf.children = children;
    asf.order = order;
    Ok(())
}

/// Per node: where its values go and how to turn them into channel values.
struct NodeLayout {
    dofs: Vec<Dof>,
    /// `C` and `C⁻¹` of the node's axis frame.
    frame: DQuat,
    frame_inv: DQuat,
    /// First channel of the node's joint in a frame vector.
    channel_start: usize,
}

/// Parses AMC frames into frame-major channel values of the converted skeleton.
fn parse_amc(asf: &Asf, text: &str, file: &str) -> Result<Vec<f64>, IoError> {
    let n = asf.bones.len() + 1;
    let mut layouts: Vec<NodeLayout> = Vec::with_capacity(n);
    let mut channel = vec![0usize; n];
    let mut next = 0;
    for &node in &asf.order {
        channel[node] = next;
        next += if node == 0 { 6 } else { 3 };
    }
    let nc = next;
    for (node, &channel_start) in channel.iter().enumerate() {
        let frame = asf.axis_frame(node);
        let dofs = if node == 0 {
            asf.root_order.clone()
        } else {
            asf.bones[node - 1].dofs.iter().map(|&a| Dof::Rotate(a)).collect()
        };
        layouts.push(NodeLayout { dofs, frame, frame_inv: frame.inverse(), channel_start });
    }
    let mut node_of: HashMap<&str, usize> = HashMap::with_capacity(n);
    node_of.insert("root", 0);
    for (i, b) in asf.bones.iter().enumerate() {
        node_of.insert(b.name.as_str(), i + 1);
    }

    let mut angle_to_rad = asf.angle_to_rad;
    let mut data: Vec<f64> = Vec::with_capacity((text.len() / 8).min(1 << 24));
    let mut frame = FrameBuilder { seen: vec![false; n], values: vec![0.0; 12 * n], number: None, line: 0 };
    let mut header = true;
    for (line, text) in clean_lines(text) {
        let mut words = text.split_ascii_whitespace();
        let Some(first) = words.next() else { continue };
        if first.starts_with(':') {
            if !header {
                return Err(syntax(file, line, "a frame number or bone values", crate::lexer::quote(first)));
            }
            match first.to_ascii_uppercase().as_str() {
                ":DEGREES" => angle_to_rad = 1f64.to_radians(),
                ":RADIANS" => angle_to_rad = 1.0,
                _ => {}
            }
            continue;
        }
        header = false;
        if first.bytes().all(|b| b.is_ascii_digit()) {
            if let Some(extra) = words.next() {
                return Err(syntax(file, line, "only a frame number on the line", crate::lexer::quote(extra)));
            }
            let number: u64 =
                first.parse().map_err(|_| syntax(file, line, "a frame number", crate::lexer::quote(first)))?;
            if let Some(prev) = frame.number {
                frame.finish(asf, &layouts, nc, angle_to_rad, &mut data, file)?;
                if Some(number) != prev.checked_add(1) {
                    return Err(syntax(
                        file,
                        line,
                        format!("frame number {}", prev.saturating_add(1)),
                        format!("{number}"),
                    ));
                }
            }
            frame.start(number, line);
            continue;
        }
        let Some(_) = frame.number else {
            return Err(syntax(file, line, "a frame number before bone values", crate::lexer::quote(first)));
        };
        let node = *node_of
            .get(first)
            .ok_or_else(|| syntax(file, line, "a bone named in the ASF file", crate::lexer::quote(first)))?;
        if frame.seen[node] {
            return Err(invalid(
                file,
                line,
                format!("bone '{first}' appears twice in frame {}", frame.number.unwrap_or(0)),
            ));
        }
        frame.seen[node] = true;
        let k = layouts[node].dofs.len();
        let mut got = 0;
        for w in words {
            if got == k {
                return Err(syntax(file, line, format!("{k} values for '{first}' (its dof)"), "more".into()));
            }
            let v = crate::lexer::parse_finite(w)
                .ok_or_else(|| syntax(file, line, format!("a finite number for '{first}'"), crate::lexer::quote(w)))?;
            frame.values[node * 6 + got] = v;
            got += 1;
        }
        if got != k {
            return Err(syntax(file, line, format!("{k} values for '{first}' (its dof)"), format!("{got}")));
        }
    }
    if frame.number.is_some() {
        frame.finish(asf, &layouts, nc, angle_to_rad, &mut data, file)?;
    }
    Ok(data)
}

/// The frame being read: which bones have been seen and their raw values (6 slots per node).
struct FrameBuilder {
    seen: Vec<bool>,
    values: Vec<f64>,
    number: Option<u64>,
    line: usize,
}

impl FrameBuilder {
    fn start(&mut self, number: u64, line: usize) {
        self.number = Some(number);
        self.line = line;
        self.seen.iter_mut().for_each(|s| *s = false);
    }

    /// Converts the finished frame to channel values: `L = C · M · C⁻¹` per node, as ZYX degrees.
    fn finish(
        &self,
        asf: &Asf,
        layouts: &[NodeLayout],
        nc: usize,
        angle_to_rad: f64,
        data: &mut Vec<f64>,
        file: &str,
    ) -> Result<(), IoError> {
        let start = data.len();
        data.resize(start + nc, 0.0);
        let out = &mut data[start..];
        for (node, layout) in layouts.iter().enumerate() {
            if !layout.dofs.is_empty() && !self.seen[node] {
                return Err(invalid(
                    file,
                    self.line,
                    format!("frame {} has no values for '{}'", self.number.unwrap_or(0), asf.name(node)),
                ));
            }
            let raw = &self.values[node * 6..node * 6 + layout.dofs.len()];
            let mut translation = asf.root_position;
            let mut m = DQuat::IDENTITY;
            for (d, &v) in layout.dofs.iter().zip(raw) {
                match d {
                    Dof::Rotate(a) => m = a.rotation(v * angle_to_rad) * m,
                    Dof::Translate(a) => translation[a.index()] = v,
                }
            }
            let local = layout.frame * m * layout.frame_inv;
            let angles = OUTPUT_ORDER.from_quat(local).map(f64::to_degrees);
            let mut c = layout.channel_start;
            if node == 0 {
                out[c..c + 3].copy_from_slice(&translation.to_array());
                c += 3;
            }
            out[c..c + 3].copy_from_slice(&angles);
        }
        Ok(())
    }
}
