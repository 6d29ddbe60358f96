//! BVH (Biovision Hierarchy) reader and writer.
//!
//! Reads any channel layout the core [`Skeleton`] can hold: 0, 3 or 6 channels per joint (also
//! position-only), rotation and position channels in any order, all six Euler orders, `End Site`
//! blocks, LF/CRLF/mixed line ends, tabs or runs of spaces. The hierarchy is parsed without recursion
//! and nothing is allocated from the declared `Frames:` count alone, so hostile input costs at most
//! memory proportional to its own size.

use crate::lexer::{describe, parse_finite, quote, Lexer, Token};
use crate::{read_text, IoError};
use glam::DVec3;
use inbetween_core::{Channel, Joint, Motion, Skeleton};
use std::collections::HashSet;
use std::fmt::Write as _;
use std::path::Path;

/// Reads a BVH file.
pub fn read_bvh(path: &Path) -> Result<Motion, IoError> {
    let text = read_text(path)?;
    parse_bvh(&text, &path.display().to_string())
}

/// Writes `motion` as BVH, atomically (temporary file + rename).
pub fn write_bvh(path: &Path, motion: &Motion) -> Result<(), IoError> {
    crate::fsutil::write_atomic(path, to_bvh_string(motion).as_bytes())
        .map_err(|source| IoError::Io { path: path.to_path_buf(), source })
}

/// Parses BVH text; `source_name` names the file in error messages.
pub fn parse_bvh(text: &str, source_name: &str) -> Result<Motion, IoError> {
    let mut p = Parser { lx: Lexer::new(text), file: source_name };
    let skeleton = p.hierarchy()?;
    p.motion(skeleton, text.len())
}

/// What the hierarchy parser is inside of.
enum Block {
    Joint { index: usize, has_offset: bool, has_channels: bool },
    EndSite { owner: usize, has_offset: bool },
}

struct Parser<'a> {
    lx: Lexer<'a>,
    file: &'a str,
}

impl<'a> Parser<'a> {
    fn syntax(&self, line: usize, expected: impl Into<String>, found: String) -> IoError {
        IoError::Syntax { file: self.file.to_string(), line, expected: expected.into(), found }
    }

    fn invalid(&self, line: usize, message: impl Into<String>) -> IoError {
        IoError::Invalid { file: self.file.to_string(), line, message: message.into() }
    }

    /// The next token, which must exist.
    fn token(&mut self, expected: &str) -> Result<Token<'a>, IoError> {
        let line = self.lx.line();
        self.lx.next_token().ok_or_else(|| self.syntax(line, expected, describe(None)))
    }

    fn keyword(&mut self, word: &str) -> Result<Token<'a>, IoError> {
        let t = self.token(&format!("'{word}'"))?;
        if t.text.eq_ignore_ascii_case(word) {
            Ok(t)
        } else {
            Err(self.syntax(t.line, format!("'{word}'"), quote(t.text)))
        }
    }

    fn number(&mut self, what: &str) -> Result<f64, IoError> {
        let t = self.token(what)?;
        parse_finite(t.text).ok_or_else(|| self.syntax(t.line, what, quote(t.text)))
    }

    fn vec3(&mut self, what: &str) -> Result<DVec3, IoError> {
        let x = self.number(&format!("{what} x (a finite number)"))?;
        let y = self.number(&format!("{what} y (a finite number)"))?;
        let z = self.number(&format!("{what} z (a finite number)"))?;
        Ok(DVec3::new(x, y, z))
    }

    /// A joint name: the rest of the line, allowing a `{` at its end. Returns (name, brace seen).
    fn joint_name(&mut self, keyword_line: usize) -> Result<(&'a str, bool), IoError> {
        let rest = self.lx.rest_of_line();
        let (name, brace) = match rest.strip_suffix('{') {
            Some(n) => (n.trim_end(), true),
            None => (rest, false),
        };
        if name.is_empty() {
            return Err(self.syntax(keyword_line, "a joint name", "end of line".into()));
        }
        Ok((name, brace))
    }

    fn hierarchy(&mut self) -> Result<Skeleton, IoError> {
        self.keyword("HIERARCHY")?;
        let root = self.keyword("ROOT")?;
        let mut joints: Vec<Joint> = Vec::new();
        let mut names: HashSet<&'a str> = HashSet::new();
        let mut stack: Vec<Block> = Vec::new();
        self.open_joint(root.line, None, &mut joints, &mut names, &mut stack)?;
        while let Some(top) = stack.last_mut() {
            match top {
                Block::Joint { index, has_offset, has_channels } => {
                    let index = *index;
                    let expected =
                        format!("OFFSET, CHANNELS, JOINT, End Site or '}}' inside joint '{}'", joints[index].name);
                    let t = self.token(&expected)?;
                    match t.text.to_ascii_uppercase().as_str() {
                        "OFFSET" if !*has_offset => {
                            *has_offset = true;
                            joints[index].offset = self.vec3("OFFSET")?;
                        }
                        "CHANNELS" if !*has_channels => {
                            *has_channels = true;
                            joints[index].channels = self.channels(t.line)?;
                        }
                        "JOINT" => self.open_joint(t.line, Some(index), &mut joints, &mut names, &mut stack)?,
                        "END" => {
                            self.keyword("Site")?;
                            if joints[index].end_site.is_some() {
                                return Err(self
                                    .invalid(t.line, format!("joint '{}' has a second End Site", joints[index].name)));
                            }
                            self.keyword("{")?;
                            joints[index].end_site = Some(DVec3::ZERO);
                            stack.push(Block::EndSite { owner: index, has_offset: false });
                        }
                        "}" => {
                            stack.pop();
                        }
                        _ => return Err(self.syntax(t.line, expected, quote(t.text))),
                    }
                }
                Block::EndSite { owner, has_offset } => {
                    let owner = *owner;
                    let t = self.token("OFFSET or '}' inside End Site")?;
                    match t.text.to_ascii_uppercase().as_str() {
                        "OFFSET" if !*has_offset => {
                            *has_offset = true;
                            joints[owner].end_site = Some(self.vec3("End Site OFFSET")?);
                        }
                        "}" => {
                            stack.pop();
                        }
                        _ => return Err(self.syntax(t.line, "OFFSET or '}' inside End Site", quote(t.text))),
                    }
                }
            }
        }
        Skeleton::new(joints).map_err(|e| self.invalid(root.line, e.to_string()))
    }

    fn open_joint(
        &mut self,
        keyword_line: usize,
        parent: Option<usize>,
        joints: &mut Vec<Joint>,
        names: &mut HashSet<&'a str>,
        stack: &mut Vec<Block>,
    ) -> Result<(), IoError> {
        let (name, brace) = self.joint_name(keyword_line)?;
        if !names.insert(name) {
            return Err(self.invalid(keyword_line, format!("joint name '{name}' appears twice")));
        }
        if !brace {
            self.keyword("{")?;
        }
        stack.push(Block::Joint { index: joints.len(), has_offset: false, has_channels: false });
        joints.push(Joint {
            name: name.to_string(),
            parent,
            offset: DVec3::ZERO,
            channels: Vec::new(),
            end_site: None,
        });
        Ok(())
    }

    /// `CHANNELS n name…`: at most six, no repeats, rotations none or all three axes.
    fn channels(&mut self, line: usize) -> Result<Vec<Channel>, IoError> {
        let t = self.token("a channel count")?;
        let n: usize = match t.text.parse() {
            Ok(n) if n <= 6 => n,
            _ => return Err(self.syntax(t.line, "a channel count from 0 to 6", quote(t.text))),
        };
        let mut channels = Vec::with_capacity(n);
        for _ in 0..n {
            let c = self.token("a channel name (Xposition … Zrotation)")?;
            let ch = Channel::parse(c.text)
                .ok_or_else(|| self.syntax(c.line, "a channel name (Xposition … Zrotation)", quote(c.text)))?;
            if channels.contains(&ch) {
                return Err(self.invalid(c.line, format!("channel {} appears twice", ch.name())));
            }
            channels.push(ch);
        }
        let rotations = channels.iter().filter(|c| c.is_rotation()).count();
        if rotations != 0 && rotations != 3 {
            return Err(
                self.invalid(line, format!("{rotations} rotation channels; expected none or all three of X, Y, Z"))
            );
        }
        Ok(channels)
    }

    fn motion(mut self, skeleton: Skeleton, text_len: usize) -> Result<Motion, IoError> {
        let t = self.token("'MOTION'")?;
        if !t.text.eq_ignore_ascii_case("MOTION") {
            let hint =
                if t.text.eq_ignore_ascii_case("ROOT") { "'MOTION' (only one ROOT is supported)" } else { "'MOTION'" };
            return Err(self.syntax(t.line, hint, quote(t.text)));
        }
        let frames_tok = self.keyword("Frames:")?;
        let t = self.token("a frame count")?;
        let frames: u64 =
            t.text.parse().map_err(|_| self.syntax(t.line, "a frame count (a whole number)", quote(t.text)))?;
        self.keyword("Frame")?;
        self.keyword("Time:")?;
        let t = self.token("a frame time in seconds")?;
        let frame_time = parse_finite(t.text)
            .filter(|&v| v > 0.0)
            .ok_or_else(|| self.syntax(t.line, "a positive frame time in seconds", quote(t.text)))?;

        let nc = skeleton.num_channels();
        // Each value takes at least two bytes (digit + separator), which bounds the allocation by
        // the input size whatever `Frames:` claims.
        let cap = (frames as usize).saturating_mul(nc).min(text_len / 2 + nc);
        let mut data: Vec<f64> = Vec::with_capacity(cap);
        let mut read: u64 = 0;
        let mut last_line = t.line;
        let mut lines = self.lx.clone().remaining_lines();
        if let Some((line, rest)) = lines.next() {
            if let Some(extra) = rest.split_ascii_whitespace().next() {
                return Err(self.syntax(line, "the end of the 'Frame Time:' line", quote(extra)));
            }
        }
        for (line, text) in lines {
            last_line = line;
            if text.trim_ascii().is_empty() {
                continue;
            }
            if nc == 0 {
                return Err(self.syntax(line, "no motion data (the skeleton has no channels)", quote(text.trim())));
            }
            if read == frames {
                return Err(self.syntax(
                    line,
                    format!("end of file after {frames} frames (declared by 'Frames:' on line {})", frames_tok.line),
                    "another line of motion data".into(),
                ));
            }
            let before = data.len();
            for (c, word) in text.split_ascii_whitespace().enumerate() {
                if c >= nc {
                    return Err(self.syntax(
                        line,
                        format!("{nc} values in frame {read} (one per channel)"),
                        format!("more ({})", text.split_ascii_whitespace().count()),
                    ));
                }
                let v = parse_finite(word).ok_or_else(|| {
                    self.syntax(
                        line,
                        format!("a finite number for frame {read}, channel {c} ({})", channel_label(&skeleton, c)),
                        quote(word),
                    )
                })?;
                data.push(v);
            }
            let got = data.len() - before;
            if got != nc {
                return Err(self.syntax(
                    line,
                    format!("{nc} values in frame {read} (one per channel)"),
                    format!("{got}"),
                ));
            }
            read += 1;
        }
        if read != frames && nc > 0 {
            return Err(self.syntax(
                last_line,
                format!("{frames} frames (declared by 'Frames:' on line {})", frames_tok.line),
                format!("{read} lines of motion data"),
            ));
        }
        Motion::new(skeleton, frame_time, data).map_err(|e| self.invalid(frames_tok.line, e.to_string()))
    }
}

/// "joint Xrotation" for the `c`-th channel of a frame.
fn channel_label(skeleton: &Skeleton, c: usize) -> String {
    for (j, joint) in skeleton.joints().iter().enumerate() {
        let start = skeleton.channel_start(j);
        if c >= start && c < start + joint.channels.len() {
            return format!("{} {}", joint.name, joint.channels[c - start].name());
        }
    }
    format!("channel {c}")
}

/// Joints in depth-first order (children in index order): the order a BVH file lists them, and
/// therefore the order of each motion line's values.
fn depth_first_order(skeleton: &Skeleton) -> Vec<usize> {
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); skeleton.len()];
    for (j, joint) in skeleton.joints().iter().enumerate() {
        if let Some(p) = joint.parent {
            children[p].push(j);
        }
    }
    let mut order = Vec::with_capacity(skeleton.len());
    let mut stack = vec![0];
    while let Some(j) = stack.pop() {
        order.push(j);
        stack.extend(children[j].iter().rev());
    }
    order
}

fn write_vec3(out: &mut String, v: DVec3) {
    let _ = write!(out, "{:.6} {:.6} {:.6}", v.x, v.y, v.z);
}

/// BVH text of `motion`: offsets and values with 6 decimals, the frame time in full precision.
/// Joints are written depth-first (the only order BVH can express); a skeleton already in that
/// order, as every parsed BVH is, reads back with identical joint indices. Joint names must be
/// non-empty and on one line.
pub fn to_bvh_string(motion: &Motion) -> String {
    let skeleton = &motion.skeleton;
    let order = depth_first_order(skeleton);
    let mut out = String::with_capacity(256 * skeleton.len() + motion.data().len() * 11);
    out.push_str("HIERARCHY\n");
    write_hierarchy(&mut out, skeleton);
    let _ = write!(out, "MOTION\nFrames: {}\nFrame Time: {}\n", motion.num_frames(), motion.frame_time);
    for f in 0..motion.num_frames() {
        let frame = motion.frame(f);
        let mut first = true;
        for &j in &order {
            let start = skeleton.channel_start(j);
            for v in &frame[start..start + skeleton.joint(j).channels.len()] {
                if !first {
                    out.push(' ');
                }
                first = false;
                let _ = write!(out, "{v:.6}");
            }
        }
        out.push('\n');
    }
    out
}

/// The hierarchy, written without recursion (skeletons read from files can be arbitrarily deep).
fn write_hierarchy(out: &mut String, skeleton: &Skeleton) {
    enum Step {
        Open(usize),
        Close(usize),
    }
    let mut depth = vec![0usize; skeleton.len()];
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); skeleton.len()];
    for (j, joint) in skeleton.joints().iter().enumerate() {
        if let Some(p) = joint.parent {
            children[p].push(j);
            depth[j] = depth[p] + 1;
        }
    }
    let indent = |out: &mut String, d: usize| out.extend(std::iter::repeat_n('\t', d));
    let mut stack = vec![Step::Open(0)];
    while let Some(step) = stack.pop() {
        match step {
            Step::Open(j) => {
                let joint = skeleton.joint(j);
                let d = depth[j];
                indent(out, d);
                let _ = writeln!(out, "{} {}", if joint.parent.is_none() { "ROOT" } else { "JOINT" }, joint.name);
                indent(out, d);
                out.push_str("{\n");
                indent(out, d + 1);
                out.push_str("OFFSET ");
                write_vec3(out, joint.offset);
                out.push('\n');
                indent(out, d + 1);
                let _ = write!(out, "CHANNELS {}", joint.channels.len());
                for c in &joint.channels {
                    out.push(' ');
                    out.push_str(c.name());
                }
                out.push('\n');
                stack.push(Step::Close(j));
                stack.extend(children[j].iter().rev().map(|&c| Step::Open(c)));
            }
            Step::Close(j) => {
                let d = depth[j];
                if let Some(e) = skeleton.joint(j).end_site {
                    indent(out, d + 1);
                    out.push_str("End Site\n");
                    indent(out, d + 1);
                    out.push_str("{\n");
                    indent(out, d + 2);
                    out.push_str("OFFSET ");
                    write_vec3(out, e);
                    out.push('\n');
                    indent(out, d + 1);
                    out.push_str("}\n");
                }
                indent(out, d);
                out.push_str("}\n");
            }
        }
    }
}
