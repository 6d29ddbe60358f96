//! The binary side of a glTF 2.0 document, shared by every engine that writes glTF (camera tracks,
//! furnished and animated scenes): one binary buffer (buffer 0) cut into `bufferView`s, and the
//! `accessor`s that type them. Documents, nodes, meshes, materials and animations stay with their
//! writers; this module only lays out bytes and describes them the way the spec asks.
//!
//! Layout: every bufferView starts on a 4-byte boundary (glTF 2.0 §3.6.2.4, "data alignment":
//! an accessor's offset must be a multiple of its component size), so the buffer is zero-padded
//! before each view; float data is `componentType` 5126 (FLOAT), indices 5123 (UNSIGNED_SHORT),
//! little-endian. A view for vertex attributes may name `target` 34962 (ARRAY_BUFFER), one for
//! indices 34963 (ELEMENT_ARRAY_BUFFER); animation data names none.
//!
//! ```
//! use inbetween_io::gltf_buffer::{ElementType, GltfBuffer, ARRAY_BUFFER};
//! let mut b = GltfBuffer::default();
//! let pos = b.floats(&[0.0, 0.0, 0.0, 1.0, 2.0, 3.0], ElementType::Vec3, true, Some(ARRAY_BUFFER));
//! let idx = b.indices(&[0, 1, 1]);
//! assert_eq!((pos, idx), (0, 1));
//! assert_eq!(b.accessors[pos]["max"], serde_json::json!([1.0, 2.0, 3.0]));
//! assert_eq!(b.views[1]["byteOffset"], 24); // the index view follows the 24 bytes of positions
//! ```

use serde_json::{json, Value};

/// `componentType` of 32-bit IEEE floats.
pub const FLOAT: u32 = 5126;
/// `componentType` of unsigned 16-bit integers (our mesh indices).
pub const UNSIGNED_SHORT: u32 = 5123;
/// bufferView `target` for vertex attributes (ARRAY_BUFFER).
pub const ARRAY_BUFFER: u32 = 34962;
/// bufferView `target` for vertex indices (ELEMENT_ARRAY_BUFFER).
pub const ELEMENT_ARRAY_BUFFER: u32 = 34963;

/// An accessor's `type`: how many components make one element.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ElementType {
    Scalar,
    Vec2,
    Vec3,
    Vec4,
    Mat4,
}

impl ElementType {
    /// Components per element (1, 2, 3, 4 or 16).
    pub fn components(self) -> usize {
        match self {
            ElementType::Scalar => 1,
            ElementType::Vec2 => 2,
            ElementType::Vec3 => 3,
            ElementType::Vec4 => 4,
            ElementType::Mat4 => 16,
        }
    }

    /// The accessor `type` string of the spec.
    pub fn name(self) -> &'static str {
        match self {
            ElementType::Scalar => "SCALAR",
            ElementType::Vec2 => "VEC2",
            ElementType::Vec3 => "VEC3",
            ElementType::Vec4 => "VEC4",
            ElementType::Mat4 => "MAT4",
        }
    }
}

/// Zero-pads `bin` to a multiple of 4 bytes (the next bufferView's, or the GLB BIN chunk's,
/// alignment).
pub fn pad_to_4(bin: &mut Vec<u8>) {
    bin.resize(bin.len().next_multiple_of(4), 0);
}

/// Appends `bytes` to `bin` on a 4-byte boundary and returns the bufferView describing them
/// (buffer 0, with `target` when given). For writers that keep their views elsewhere than in a
/// [`GltfBuffer`], e.g. inside a document being extended.
pub fn append_view(bin: &mut Vec<u8>, bytes: &[u8], target: Option<u32>) -> Value {
    pad_to_4(bin);
    let mut v = json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()});
    if let Some(t) = target {
        v["target"] = json!(t);
    }
    bin.extend_from_slice(bytes);
    v
}

/// Little-endian bytes of floats (FLOAT components).
pub fn f32_bytes(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// Little-endian bytes of 16-bit indices (UNSIGNED_SHORT components).
pub fn u16_bytes(values: &[u16]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// Per-component minimum and maximum over the elements of `values` (`n` components each). The
/// spec requires them on POSITION accessors and on animation inputs (times); with no elements
/// they stay at (`f32::MAX`, `f32::MIN`).
pub fn float_bounds(values: &[f32], n: usize) -> (Vec<f32>, Vec<f32>) {
    let (mut lo, mut hi) = (vec![f32::MAX; n], vec![f32::MIN; n]);
    for e in values.chunks_exact(n) {
        for k in 0..n {
            lo[k] = lo[k].min(e[k]);
            hi[k] = hi[k].max(e[k]);
        }
    }
    (lo, hi)
}

/// The FLOAT accessor over bufferView `view` holding `values` as elements of `kind`, with `min`
/// and `max` when `bounds`. `values.len()` must be a multiple of `kind.components()`.
pub fn float_accessor(view: usize, values: &[f32], kind: ElementType, bounds: bool) -> Value {
    let n = kind.components();
    debug_assert_eq!(values.len() % n, 0, "{} floats do not make whole {} elements", values.len(), kind.name());
    let mut acc = json!({"bufferView": view, "componentType": FLOAT, "count": values.len() / n, "type": kind.name()});
    if bounds {
        let (lo, hi) = float_bounds(values, n);
        acc["min"] = json!(lo);
        acc["max"] = json!(hi);
    }
    acc
}

/// The UNSIGNED_SHORT SCALAR accessor of `count` indices over bufferView `view`.
pub fn u16_index_accessor(view: usize, count: usize) -> Value {
    json!({"bufferView": view, "componentType": UNSIGNED_SHORT, "count": count, "type": "SCALAR"})
}

/// A binary buffer under construction with its bufferViews and accessors, indexed as they will
/// appear in the document's `bufferViews` and `accessors` arrays.
#[derive(Debug, Clone, Default)]
pub struct GltfBuffer {
    /// Buffer 0's bytes.
    pub bin: Vec<u8>,
    /// The document's `bufferViews`.
    pub views: Vec<Value>,
    /// The document's `accessors`.
    pub accessors: Vec<Value>,
}

impl GltfBuffer {
    /// Adds `bytes` as a new bufferView (4-byte aligned, `target` when given); returns its index.
    pub fn view(&mut self, bytes: &[u8], target: Option<u32>) -> usize {
        let v = append_view(&mut self.bin, bytes, target);
        self.views.push(v);
        self.views.len() - 1
    }

    /// Adds `values` as a FLOAT accessor of `kind` elements in a view of its own (see
    /// [`float_accessor`]); returns the accessor's index.
    pub fn floats(&mut self, values: &[f32], kind: ElementType, bounds: bool, target: Option<u32>) -> usize {
        let view = self.view(&f32_bytes(values), target);
        self.accessors.push(float_accessor(view, values, kind, bounds));
        self.accessors.len() - 1
    }

    /// Adds triangle indices as an UNSIGNED_SHORT accessor in an ELEMENT_ARRAY_BUFFER view;
    /// returns the accessor's index.
    pub fn indices(&mut self, idx: &[u16]) -> usize {
        let view = self.view(&u16_bytes(idx), Some(ELEMENT_ARRAY_BUFFER));
        self.accessors.push(u16_index_accessor(view, idx.len()));
        self.accessors.len() - 1
    }

    /// Zero-pads the buffer to a multiple of 4 bytes (before merging foreign data or finishing).
    pub fn align(&mut self) {
        pad_to_4(&mut self.bin);
    }
}

/// The `uri` that embeds a buffer in a `.gltf` file.
pub fn data_uri(bin: &[u8]) -> String {
    format!("data:application/octet-stream;base64,{}", base64(bin))
}

/// Standard base64 with `=` padding (RFC 4648 §4), as data URIs use.
pub fn base64(bytes: &[u8]) -> String {
    use base64::Engine;
    base64::engine::general_purpose::STANDARD.encode(bytes)
}

/// Decodes [`base64`] text (padding optional, as in data URIs of other tools); None on text that
/// is not base64.
pub fn base64_decode(text: &str) -> Option<Vec<u8>> {
    use base64::engine::{general_purpose::GeneralPurpose, DecodePaddingMode, GeneralPurposeConfig};
    use base64::Engine;
    const LENIENT: GeneralPurpose = GeneralPurpose::new(
        &base64::alphabet::STANDARD,
        GeneralPurposeConfig::new().with_decode_padding_mode(DecodePaddingMode::Indifferent),
    );
    LENIENT.decode(text).ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn float_accessor_counts_elements_and_bounds_each_component() {
        let mut b = GltfBuffer::default();
        let a = b.floats(&[1.0, -2.0, 3.0, -1.0, 5.0, 0.5], ElementType::Vec3, true, Some(ARRAY_BUFFER));
        let acc = &b.accessors[a];
        assert_eq!(acc["count"], 2);
        assert_eq!(acc["type"], "VEC3");
        assert_eq!(acc["componentType"], FLOAT);
        assert_eq!(acc["min"], json!([-1.0, -2.0, 0.5]));
        assert_eq!(acc["max"], json!([1.0, 5.0, 3.0]));
        assert_eq!(b.views[0]["target"], ARRAY_BUFFER);
        assert_eq!(b.views[0]["byteLength"], 24);
        assert_eq!(&b.bin[..4], &1.0f32.to_le_bytes());
    }

    #[test]
    fn accessors_without_bounds_or_target_leave_those_keys_out() {
        let mut b = GltfBuffer::default();
        let a = b.floats(&[0.0, 0.0, 0.0, 1.0], ElementType::Vec4, false, None);
        assert!(b.accessors[a].get("min").is_none() && b.accessors[a].get("max").is_none());
        assert!(b.views[0].get("target").is_none());
        assert_eq!(b.accessors[a]["type"], "VEC4");
    }

    #[test]
    fn every_view_starts_on_four_bytes_after_odd_index_data() {
        let mut b = GltfBuffer::default();
        let i = b.indices(&[0, 1, 2]); // 6 bytes: the next view needs 2 bytes of padding
        let f = b.floats(&[0.25, 0.5], ElementType::Vec2, false, None);
        assert_eq!(b.accessors[i]["componentType"], UNSIGNED_SHORT);
        assert_eq!(b.accessors[i]["count"], 3);
        assert_eq!(b.views[0]["target"], ELEMENT_ARRAY_BUFFER);
        assert_eq!(b.views[1]["byteOffset"], 8);
        assert_eq!(&b.bin[6..8], &[0, 0]);
        assert_eq!(b.accessors[f]["bufferView"], 1);
        assert_eq!(b.accessors[f]["type"], "VEC2");
        assert_eq!(b.bin.len(), 16);
        let mut odd = GltfBuffer::default();
        odd.view(&[7], None);
        odd.align();
        assert_eq!(odd.bin, [7, 0, 0, 0]);
    }

    #[test]
    fn append_view_extends_a_buffer_held_elsewhere() {
        let mut bin = vec![1, 2, 3, 4, 5];
        let v = append_view(&mut bin, &[9, 9], Some(ARRAY_BUFFER));
        assert_eq!(v, json!({"buffer": 0, "byteOffset": 8, "byteLength": 2, "target": ARRAY_BUFFER}));
        assert_eq!(bin, [1, 2, 3, 4, 5, 0, 0, 0, 9, 9]);
    }

    #[test]
    fn element_types_match_the_spec_names_and_sizes() {
        let all = [ElementType::Scalar, ElementType::Vec2, ElementType::Vec3, ElementType::Vec4, ElementType::Mat4];
        let names: Vec<_> = all.iter().map(|t| (t.name(), t.components())).collect();
        assert_eq!(names, [("SCALAR", 1), ("VEC2", 2), ("VEC3", 3), ("VEC4", 4), ("MAT4", 16)]);
    }

    #[test]
    fn bounds_of_no_elements_stay_at_the_extremes() {
        assert_eq!(float_bounds(&[], 1), (vec![f32::MAX], vec![f32::MIN]));
        assert_eq!(float_bounds(&[3.0, 1.0, 2.0], 1), (vec![1.0], vec![3.0]));
    }

    #[test]
    fn base64_matches_rfc_4648_vectors_and_round_trips() {
        for (plain, coded) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(plain.as_bytes()), coded);
            assert_eq!(base64_decode(coded).unwrap(), plain.as_bytes());
        }
        let all: Vec<u8> = (0..=255).collect();
        assert_eq!(base64_decode(&base64(&all)).unwrap(), all);
        assert_eq!(base64_decode("Zm9v!"), None);
        assert!(data_uri(b"M").ends_with(";base64,TQ=="));
    }
}
