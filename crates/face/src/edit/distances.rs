//! The six key distances of §3.3 (after Berson et al. 2019), defined on ARKit blendshapes.
//!
//! The paper measures them between mesh vertices: three upper-to-lower-lip gaps along the mouth
//! (left, centre, right), the distance between the mouth corners, and the opening of each eyelid.
//! ARKit gives weights, not a mesh, so each distance here is an affine function of the weights,
//! `d_k = base_k + Σ_i W[k][i]·x_i`, with coefficients read off what each shape does on Apple's
//! reference face: `JawOpen` parts the lips fully, `MouthClose` shuts them again against an open jaw,
//! `MouthUpperUp*`/`MouthLowerDown*` lift and drop one side of each lip, `MouthFunnel` rounds them open,
//! `MouthRoll*`/`MouthPress*` press them together; corners move apart with `MouthSmile*`,
//! `MouthStretch*` and `MouthDimple*`, together with `MouthPucker` and `MouthFunnel`; an eyelid closes
//! with `EyeBlink*`, narrows with `EyeSquint*`/`CheekSquint*` and widens with `EyeWide*`.
//! Being affine, the distance loss is one matrix product (`DISTANCE_MATRIX`), and the critic gets the
//! same six curves. Values are in blendshape units: 0 is closed, about 1 is fully open (eyes) or the
//! rest width (mouth).

use crate::data::{arkit_index, NUM_ARKIT};

/// Number of key distances.
pub const NUM_DISTANCES: usize = 6;

/// Names of the six distances, in output order.
pub const DISTANCE_NAMES: [&str; NUM_DISTANCES] =
    ["lip_gap_left", "lip_gap_center", "lip_gap_right", "mouth_width", "eyelid_left", "eyelid_right"];

/// `(distance, base, [(shape, coefficient)])`: the definition in words of the module docs.
const TERMS: [(f32, &[(&str, f32)]); NUM_DISTANCES] = [
    (
        0.0,
        &[
            ("JawOpen", 1.0),
            ("MouthClose", -1.0),
            ("MouthUpperUpLeft", 0.5),
            ("MouthLowerDownLeft", 0.5),
            ("MouthFunnel", 0.3),
            ("MouthRollUpper", -0.2),
            ("MouthRollLower", -0.2),
            ("MouthPressLeft", -0.3),
        ],
    ),
    (
        0.0,
        &[
            ("JawOpen", 1.0),
            ("MouthClose", -1.0),
            ("MouthUpperUpLeft", 0.25),
            ("MouthUpperUpRight", 0.25),
            ("MouthLowerDownLeft", 0.25),
            ("MouthLowerDownRight", 0.25),
            ("MouthFunnel", 0.5),
            ("MouthRollUpper", -0.2),
            ("MouthRollLower", -0.2),
            ("MouthPressLeft", -0.15),
            ("MouthPressRight", -0.15),
        ],
    ),
    (
        0.0,
        &[
            ("JawOpen", 1.0),
            ("MouthClose", -1.0),
            ("MouthUpperUpRight", 0.5),
            ("MouthLowerDownRight", 0.5),
            ("MouthFunnel", 0.3),
            ("MouthRollUpper", -0.2),
            ("MouthRollLower", -0.2),
            ("MouthPressRight", -0.3),
        ],
    ),
    (
        1.0,
        &[
            ("MouthSmileLeft", 0.25),
            ("MouthSmileRight", 0.25),
            ("MouthStretchLeft", 0.25),
            ("MouthStretchRight", 0.25),
            ("MouthDimpleLeft", 0.1),
            ("MouthDimpleRight", 0.1),
            ("MouthPucker", -0.4),
            ("MouthFunnel", -0.3),
        ],
    ),
    (1.0, &[("EyeBlinkLeft", -1.0), ("EyeSquintLeft", -0.3), ("CheekSquintLeft", -0.1), ("EyeWideLeft", 0.4)]),
    (1.0, &[("EyeBlinkRight", -1.0), ("EyeSquintRight", -0.3), ("CheekSquintRight", -0.1), ("EyeWideRight", 0.4)]),
];

/// Constant term of each distance.
pub fn distance_bases() -> [f32; NUM_DISTANCES] {
    let mut b = [0.0; NUM_DISTANCES];
    for (k, (base, _)) in TERMS.iter().enumerate() {
        b[k] = *base;
    }
    b
}

/// The `[NUM_ARKIT, NUM_DISTANCES]` coefficient matrix, row-major: `d = base + x · W`.
pub fn distance_matrix() -> Vec<f32> {
    let mut w = vec![0.0f32; NUM_ARKIT * NUM_DISTANCES];
    for (k, (_, terms)) in TERMS.iter().enumerate() {
        for (name, c) in terms.iter() {
            let i = arkit_index(name).expect("distance terms name ARKit shapes");
            w[i * NUM_DISTANCES + k] += c;
        }
    }
    w
}

/// The six distances of one frame of 52 ARKit weights.
pub fn distances(frame: &[f32]) -> [f32; NUM_DISTANCES] {
    debug_assert_eq!(frame.len(), NUM_ARKIT);
    let mut d = distance_bases();
    for (k, (_, terms)) in TERMS.iter().enumerate() {
        for (name, c) in terms.iter() {
            d[k] += c * frame[arkit_index(name).expect("distance terms name ARKit shapes")];
        }
    }
    d
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pose(shapes: &[(&str, f32)]) -> Vec<f32> {
        let mut x = vec![0.0; NUM_ARKIT];
        for (n, v) in shapes {
            x[arkit_index(n).unwrap()] = *v;
        }
        x
    }

    #[test]
    fn neutral_face_has_closed_lips_open_eyes_and_rest_width() {
        assert_eq!(distances(&pose(&[])), [0.0, 0.0, 0.0, 1.0, 1.0, 1.0]);
    }

    #[test]
    fn shapes_move_the_distances_they_should() {
        let open = distances(&pose(&[("JawOpen", 0.8)]));
        assert!(open[..3].iter().all(|d| (*d - 0.8).abs() < 1e-6));
        let closed = distances(&pose(&[("JawOpen", 0.8), ("MouthClose", 0.8)]));
        assert!(closed[..3].iter().all(|d| d.abs() < 1e-6));
        let blink = distances(&pose(&[("EyeBlinkLeft", 1.0)]));
        assert_eq!((blink[4], blink[5]), (0.0, 1.0));
        let smile = distances(&pose(&[("MouthSmileLeft", 1.0), ("MouthSmileRight", 1.0)]));
        assert!(smile[3] > 1.4);
        let pucker = distances(&pose(&[("MouthPucker", 1.0)]));
        assert!(pucker[3] < 0.7);
        let left = distances(&pose(&[("MouthUpperUpLeft", 1.0)]));
        assert!(left[0] > left[1] && left[1] > left[2]);
    }

    #[test]
    fn matrix_form_equals_the_direct_sum() {
        let w = distance_matrix();
        let b = distance_bases();
        let x: Vec<f32> = (0..NUM_ARKIT).map(|i| ((i * 37 % 11) as f32) / 11.0).collect();
        let direct = distances(&x);
        for k in 0..NUM_DISTANCES {
            let m: f32 = b[k] + (0..NUM_ARKIT).map(|i| x[i] * w[i * NUM_DISTANCES + k]).sum::<f32>();
            assert!((m - direct[k]).abs() < 1e-5, "distance {k}: {m} vs {}", direct[k]);
        }
    }
}
