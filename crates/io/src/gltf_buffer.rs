//! Typed glTF 2.0 documents ([`gltf_json`], re-exported as [`json`]) and their one binary buffer,
//! shared by every engine that writes glTF (camera tracks, motion takes, furnished, animated and
//! skinned scenes): [`GltfDoc`] holds the document's typed structures and buffer 0, cuts the buffer
//! into `bufferView`s and types them with `accessor`s the way the spec asks; its writers add nodes,
//! meshes, materials and animations as typed structures ([`node`], [`mesh`], [`Anim`] …) and
//! [`GltfDoc::finish`] gives the JSON and the bytes for [`crate::motion_gltf::glb_bytes`] or
//! [`data_uri`].
//!
//! Layout: every bufferView starts on a 4-byte boundary (glTF 2.0 §3.6.2.4, "data alignment":
//! an accessor's offset must be a multiple of its component size), so the buffer is zero-padded
//! before each view; float data is FLOAT, mesh indices UNSIGNED_SHORT, little-endian. A view for
//! vertex attributes may name the ARRAY_BUFFER target, one for indices ELEMENT_ARRAY_BUFFER;
//! animation data names none.
//!
//! ```
//! use inbetween_io::gltf_buffer::{json, GltfDoc, Type, ARRAY_BUFFER};
//! let mut d = GltfDoc::new("doc test");
//! let pos = d.floats(&[0.0, 0.0, 0.0, 1.0, 2.0, 3.0], Type::Vec3, true, Some(ARRAY_BUFFER));
//! let idx = d.indices(&[0, 1, 1]);
//! assert_eq!((pos.value(), idx.value()), (0, 1));
//! let (doc, bin) = d.finish();
//! assert_eq!(doc["accessors"][0]["max"], serde_json::json!([1.0, 2.0, 3.0]));
//! assert_eq!(doc["bufferViews"][1]["byteOffset"], 24); // the index view follows the 24 bytes of positions
//! assert_eq!(doc["buffers"][0]["byteLength"], bin.len());
//! ```

pub use gltf_json as json;
pub use json::accessor::Type;
use json::accessor::{ComponentType, GenericComponentType};
use json::animation::{Interpolation, Property};
use json::buffer::Target;
use json::validation::{Checked::Valid, USize64};
use json::{Accessor, Index, Root};
use serde_json::Value;

/// bufferView target for vertex attributes (ARRAY_BUFFER).
pub const ARRAY_BUFFER: Target = Target::ArrayBuffer;
/// bufferView target for vertex indices (ELEMENT_ARRAY_BUFFER).
pub const ELEMENT_ARRAY_BUFFER: Target = Target::ElementArrayBuffer;

/// Zero-pads `bin` to a multiple of 4 bytes (the next bufferView's, or the GLB BIN chunk's,
/// alignment).
pub fn pad_to_4(bin: &mut Vec<u8>) {
    bin.resize(bin.len().next_multiple_of(4), 0);
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

/// A glTF document under construction: its typed structures and buffer 0's bytes.
#[derive(Debug, Clone)]
pub struct GltfDoc {
    pub root: Root,
    pub bin: Vec<u8>,
}

impl GltfDoc {
    /// An empty glTF 2.0 document naming its `generator`.
    pub fn new(generator: &str) -> GltfDoc {
        let mut root = Root::default();
        root.asset.generator = Some(generator.to_string());
        GltfDoc { root, bin: Vec::new() }
    }

    /// Adds any top-level object (node, mesh, material, camera, skin …); returns its index.
    pub fn push<T>(&mut self, value: T) -> Index<T>
    where
        Root: AsMut<Vec<T>>,
    {
        self.root.push(value)
    }

    /// Appends `bytes` on a 4-byte boundary as a new bufferView of buffer 0 (with `target` when
    /// given); returns its index.
    pub fn view(&mut self, bytes: &[u8], target: Option<Target>) -> Index<json::buffer::View> {
        pad_to_4(&mut self.bin);
        let view = json::buffer::View {
            buffer: Index::new(0),
            byte_length: USize64::from(bytes.len()),
            byte_offset: Some(USize64::from(self.bin.len())),
            byte_stride: None,
            name: None,
            target: target.map(Valid),
            extensions: None,
            extras: Default::default(),
        };
        self.bin.extend_from_slice(bytes);
        self.root.push(view)
    }

    /// An accessor of `count` elements of `kind` with components of `component` over fresh
    /// bytes (a view of their own), without bounds.
    pub fn accessor(
        &mut self,
        bytes: &[u8],
        target: Option<Target>,
        component: ComponentType,
        count: usize,
        kind: Type,
    ) -> Index<Accessor> {
        let view = self.view(bytes, target);
        self.root.push(accessor(view, component, count, kind))
    }

    /// `values` as a FLOAT accessor of `kind` elements in a view of its own, with per-component
    /// `min` and `max` when `bounds`. `values.len()` must be a multiple of `kind`'s size.
    pub fn floats(&mut self, values: &[f32], kind: Type, bounds: bool, target: Option<Target>) -> Index<Accessor> {
        let n = kind.multiplicity();
        debug_assert_eq!(values.len() % n, 0, "{} floats do not make whole {kind:?} elements", values.len());
        let view = self.view(&f32_bytes(values), target);
        let mut acc = accessor(view, ComponentType::F32, values.len() / n, kind);
        if bounds {
            let (lo, hi) = float_bounds(values, n);
            acc.min = Some(Value::from(lo));
            acc.max = Some(Value::from(hi));
        }
        self.root.push(acc)
    }

    /// Triangle indices as an UNSIGNED_SHORT accessor in an ELEMENT_ARRAY_BUFFER view.
    pub fn indices(&mut self, idx: &[u16]) -> Index<Accessor> {
        self.accessor(&u16_bytes(idx), Some(ELEMENT_ARRAY_BUFFER), ComponentType::U16, idx.len(), Type::Scalar)
    }

    /// Zero-pads the buffer to a multiple of 4 bytes (before merging foreign data).
    pub fn align(&mut self) {
        pad_to_4(&mut self.bin);
    }

    /// Lists `name` in `extensionsUsed` (once).
    pub fn use_extension(&mut self, name: &str) {
        if !self.root.extensions_used.iter().any(|e| e == name) {
            self.root.extensions_used.push(name.to_string());
        }
    }

    /// The finished document as JSON (buffer 0 without `uri`: add one with [`data_uri`] or write
    /// a GLB) and the buffer's bytes, padded to 4.
    pub fn finish(mut self) -> (Value, Vec<u8>) {
        pad_to_4(&mut self.bin);
        self.root.buffers = vec![json::Buffer {
            byte_length: USize64::from(self.bin.len()),
            name: None,
            uri: None,
            extensions: None,
            extras: Default::default(),
        }];
        let doc = serde_json::to_value(&self.root).expect("a glTF document serialises to JSON");
        (doc, self.bin)
    }
}

/// An accessor over a whole view, no bounds.
fn accessor(view: Index<json::buffer::View>, component: ComponentType, count: usize, kind: Type) -> Accessor {
    Accessor {
        buffer_view: Some(view),
        byte_offset: None,
        count: USize64::from(count),
        component_type: Valid(GenericComponentType(component)),
        extensions: None,
        extras: Default::default(),
        type_: Valid(kind),
        min: None,
        max: None,
        name: None,
        normalized: false,
        sparse: None,
    }
}

/// A node named `name` (no transform, mesh or children: fill in with struct update syntax).
pub fn node(name: impl Into<String>) -> json::Node {
    json::Node { name: Some(name.into()), ..Default::default() }
}

/// A mesh of one triangle primitive with `attributes`, `indices` and `material`.
pub fn mesh(
    name: impl Into<String>,
    attributes: &[(json::mesh::Semantic, Index<Accessor>)],
    indices: Option<Index<Accessor>>,
    material: Option<Index<json::Material>>,
) -> json::Mesh {
    let primitive = json::mesh::Primitive {
        attributes: attributes.iter().map(|(s, a)| (Valid(s.clone()), *a)).collect(),
        extensions: None,
        extras: Default::default(),
        indices,
        material,
        mode: Valid(json::mesh::Mode::Triangles),
        targets: None,
    };
    json::Mesh {
        extensions: None,
        extras: Default::default(),
        name: Some(name.into()),
        primitives: vec![primitive],
        weights: None,
    }
}

/// A metal-free PBR material of linear `color` (RGBA) and `roughness`.
pub fn material(name: impl Into<String>, color: [f32; 4], roughness: f32) -> json::Material {
    json::Material {
        name: Some(name.into()),
        pbr_metallic_roughness: json::material::PbrMetallicRoughness {
            base_color_factor: json::material::PbrBaseColorFactor(color),
            metallic_factor: json::material::StrengthFactor(0.0),
            roughness_factor: json::material::StrengthFactor(roughness),
            ..Default::default()
        },
        ..Default::default()
    }
}

/// A scene of `nodes`.
pub fn scene(name: Option<String>, nodes: Vec<Index<json::Node>>) -> json::Scene {
    json::Scene { extensions: None, extras: Default::default(), name, nodes }
}

/// A perspective camera (`yfov` radians; `zfar` None: infinite).
pub fn perspective(
    name: Option<String>,
    yfov: f32,
    aspect: Option<f32>,
    znear: f32,
    zfar: Option<f32>,
) -> json::Camera {
    json::Camera {
        name,
        orthographic: None,
        perspective: Some(json::camera::Perspective {
            aspect_ratio: aspect,
            yfov,
            zfar,
            znear,
            extensions: None,
            extras: Default::default(),
        }),
        type_: Valid(json::camera::Type::Perspective),
        extensions: None,
        extras: Default::default(),
    }
}

/// An animation under construction: samplers and the channels that use them.
#[derive(Debug, Clone, Default)]
pub struct Anim {
    pub samplers: Vec<json::animation::Sampler>,
    pub channels: Vec<json::animation::Channel>,
}

impl Anim {
    /// A sampler from `input` (times) to `output` values; returns its index.
    pub fn sampler(
        &mut self,
        input: Index<Accessor>,
        output: Index<Accessor>,
        interpolation: Interpolation,
    ) -> Index<json::animation::Sampler> {
        Index::push(
            &mut self.samplers,
            json::animation::Sampler {
                extensions: None,
                extras: Default::default(),
                input,
                interpolation: Valid(interpolation),
                output,
            },
        )
    }

    /// A LINEAR channel animating `path` of `node` from `input` to `output`.
    pub fn channel(
        &mut self,
        input: Index<Accessor>,
        output: Index<Accessor>,
        node: Index<json::Node>,
        path: Property,
    ) {
        let sampler = self.sampler(input, output, Interpolation::Linear);
        self.channels.push(json::animation::Channel {
            sampler,
            target: json::animation::Target { extensions: None, extras: Default::default(), node, path: Valid(path) },
            extensions: None,
            extras: Default::default(),
        });
    }

    /// The animation named `name`.
    pub fn finish(self, name: impl Into<String>) -> json::Animation {
        json::Animation {
            extensions: None,
            extras: Default::default(),
            channels: self.channels,
            name: Some(name.into()),
            samplers: self.samplers,
        }
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
        let mut d = GltfDoc::new("t");
        d.floats(&[1.0, -2.0, 3.0, -1.0, 5.0, 0.5], Type::Vec3, true, Some(ARRAY_BUFFER));
        let (doc, bin) = d.finish();
        let acc = &doc["accessors"][0];
        assert_eq!(acc["count"], 2);
        assert_eq!(acc["type"], "VEC3");
        assert_eq!(acc["componentType"], 5126);
        assert_eq!(acc["min"], serde_json::json!([-1.0, -2.0, 0.5]));
        assert_eq!(acc["max"], serde_json::json!([1.0, 5.0, 3.0]));
        assert_eq!(doc["bufferViews"][0]["target"], 34962);
        assert_eq!(doc["bufferViews"][0]["byteLength"], 24);
        assert_eq!(&bin[..4], &1.0f32.to_le_bytes());
        assert_eq!(doc["asset"]["version"], "2.0");
        assert_eq!(doc["asset"]["generator"], "t");
    }

    #[test]
    fn accessors_without_bounds_or_target_leave_those_keys_out() {
        let mut d = GltfDoc::new("t");
        d.floats(&[0.0, 0.0, 0.0, 1.0], Type::Vec4, false, None);
        let (doc, _) = d.finish();
        let acc = &doc["accessors"][0];
        assert!(acc.get("min").is_none() && acc.get("max").is_none() && acc.get("normalized").is_none());
        assert!(doc["bufferViews"][0].get("target").is_none());
        assert_eq!(acc["type"], "VEC4");
    }

    #[test]
    fn every_view_starts_on_four_bytes_after_odd_index_data() {
        let mut d = GltfDoc::new("t");
        let i = d.indices(&[0, 1, 2]); // 6 bytes: the next view needs 2 bytes of padding
        let f = d.floats(&[0.25, 0.5], Type::Vec2, false, None);
        assert_eq!((i.value(), f.value()), (0, 1));
        let (doc, bin) = d.finish();
        assert_eq!(doc["accessors"][0]["componentType"], 5123);
        assert_eq!(doc["accessors"][0]["count"], 3);
        assert_eq!(doc["bufferViews"][0]["target"], 34963);
        assert_eq!(doc["bufferViews"][1]["byteOffset"], 8);
        assert_eq!(&bin[6..8], &[0, 0]);
        assert_eq!(doc["accessors"][1]["bufferView"], 1);
        assert_eq!(doc["accessors"][1]["type"], "VEC2");
        assert_eq!(bin.len(), 16);
        let mut odd = GltfDoc::new("t");
        odd.view(&[7], None);
        assert_eq!(odd.finish().1, [7, 0, 0, 0]);
    }

    #[test]
    fn typed_parts_serialise_as_the_spec_names_them() {
        let mut d = GltfDoc::new("t");
        let p = d.floats(&[0.0; 9], Type::Vec3, true, Some(ARRAY_BUFFER));
        let m = d.push(material("red", [1.0, 0.0, 0.0, 1.0], 0.5));
        let mesh = d.push(mesh("tri", &[(json::mesh::Semantic::Positions, p)], None, Some(m)));
        let n = d.push(json::Node { mesh: Some(mesh), ..node("n") });
        d.root.scenes.push(scene(Some("s".into()), vec![n]));
        d.root.scene = Some(Index::new(0));
        let t = d.floats(&[0.0, 1.0], Type::Scalar, true, None);
        let r = d.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0], Type::Vec4, false, None);
        let mut a = Anim::default();
        a.channel(t, r, n, Property::Rotation);
        d.push(a.finish("spin"));
        d.push(perspective(None, 0.8, None, 0.05, None));
        d.use_extension("KHR_x");
        d.use_extension("KHR_x");
        let (doc, _) = d.finish();
        assert_eq!(doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"], 0);
        assert!(doc["meshes"][0]["primitives"][0].get("mode").is_none(), "TRIANGLES is the default");
        assert_eq!(
            doc["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"],
            serde_json::json!([1.0, 0.0, 0.0, 1.0])
        );
        assert_eq!(doc["nodes"][0]["mesh"], 0);
        assert_eq!(doc["animations"][0]["channels"][0]["target"], serde_json::json!({"node": 0, "path": "rotation"}));
        assert_eq!(doc["animations"][0]["samplers"][0]["interpolation"], "LINEAR");
        assert_eq!(doc["cameras"][0]["type"], "perspective");
        assert_eq!(doc["extensionsUsed"], serde_json::json!(["KHR_x"]));
        assert_eq!(doc["scene"], 0);
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
