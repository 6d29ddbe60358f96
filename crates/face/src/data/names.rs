//! Channel names: the 52 ARKit blendshapes, the 9 head/eye rotations and the 7 emotion columns of
//! the Live Link Face / NeuroSync CSV layout.

/// The 52 ARKit blendshapes in Live Link Face column order (the order of every file in
/// `../shared/data/face/neurosync`). Channel `i` of a [`super::BlendshapeClip`] is `ARKIT_NAMES[i]`.
/// Names match case-insensitively on input (`eyeBlinkLeft` in Apple's spelling is accepted) and are
/// written in this spelling.
pub const ARKIT_NAMES: [&str; 52] = [
    "EyeBlinkLeft",
    "EyeLookDownLeft",
    "EyeLookInLeft",
    "EyeLookOutLeft",
    "EyeLookUpLeft",
    "EyeSquintLeft",
    "EyeWideLeft",
    "EyeBlinkRight",
    "EyeLookDownRight",
    "EyeLookInRight",
    "EyeLookOutRight",
    "EyeLookUpRight",
    "EyeSquintRight",
    "EyeWideRight",
    "JawForward",
    "JawRight",
    "JawLeft",
    "JawOpen",
    "MouthClose",
    "MouthFunnel",
    "MouthPucker",
    "MouthRight",
    "MouthLeft",
    "MouthSmileLeft",
    "MouthSmileRight",
    "MouthFrownLeft",
    "MouthFrownRight",
    "MouthDimpleLeft",
    "MouthDimpleRight",
    "MouthStretchLeft",
    "MouthStretchRight",
    "MouthRollLower",
    "MouthRollUpper",
    "MouthShrugLower",
    "MouthShrugUpper",
    "MouthPressLeft",
    "MouthPressRight",
    "MouthLowerDownLeft",
    "MouthLowerDownRight",
    "MouthUpperUpLeft",
    "MouthUpperUpRight",
    "BrowDownLeft",
    "BrowDownRight",
    "BrowInnerUp",
    "BrowOuterUpLeft",
    "BrowOuterUpRight",
    "CheekPuff",
    "CheekSquintLeft",
    "CheekSquintRight",
    "NoseSneerLeft",
    "NoseSneerRight",
    "TongueOut",
];

/// Number of ARKit blendshapes.
pub const NUM_ARKIT: usize = ARKIT_NAMES.len();

/// Head and eye rotations of Live Link Face (radians as the app writes them; the real captures lie in
/// about -0.34..0.56). Present all nine or none; they follow the ARKit channels.
pub const HEAD_EYE_NAMES: [&str; 9] = [
    "HeadYaw",
    "HeadPitch",
    "HeadRoll",
    "LeftEyeYaw",
    "LeftEyePitch",
    "LeftEyeRoll",
    "RightEyeYaw",
    "RightEyePitch",
    "RightEyeRoll",
];

/// Number of head/eye rotation channels.
pub const NUM_HEAD_EYE: usize = HEAD_EYE_NAMES.len();

/// Emotion columns NeuroSync appends to its generated files (`Neutral` ranges 0..100). The Live Link
/// Face reader keeps them as extra channels by name; they are the only extras that format accepts.
pub const EMOTION_NAMES: [&str; 7] = ["Angry", "Disgusted", "Fearful", "Happy", "Neutral", "Sad", "Surprised"];

/// Index of an ARKit blendshape by name (case-insensitive).
pub fn arkit_index(name: &str) -> Option<usize> {
    ARKIT_NAMES.iter().position(|n| n.eq_ignore_ascii_case(name))
}

/// Index of a head/eye rotation by name (case-insensitive).
pub fn head_eye_index(name: &str) -> Option<usize> {
    HEAD_EYE_NAMES.iter().position(|n| n.eq_ignore_ascii_case(name))
}

/// Whether `name` is one of the NeuroSync emotion columns (case-insensitive).
pub fn is_emotion(name: &str) -> bool {
    EMOTION_NAMES.iter().any(|n| n.eq_ignore_ascii_case(name))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_unique_and_counted() {
        let mut all: Vec<String> =
            ARKIT_NAMES.iter().chain(&HEAD_EYE_NAMES).chain(&EMOTION_NAMES).map(|n| n.to_ascii_lowercase()).collect();
        assert_eq!(all.len(), 52 + 9 + 7);
        all.sort();
        all.dedup();
        assert_eq!(all.len(), 52 + 9 + 7, "names collide case-insensitively");
        assert_eq!(arkit_index("eyeBlinkLeft"), Some(0));
        assert_eq!(arkit_index("TongueOut"), Some(51));
        assert_eq!(head_eye_index("rightEyeRoll"), Some(8));
        assert!(is_emotion("neutral") && !is_emotion("JawOpen"));
    }
}
