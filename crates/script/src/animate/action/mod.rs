//! A character's actions (§3.2 template actions, §4.2): each SSG action's verb is read once into
//! a [`Verb`] ([`Step::read`]) and played by its own module on the character's
//! [`Builder`]:
//! - [`walk`]: locomotion to the target's stand point, or two metres ahead;
//! - [`sit`]: sitting on the target's nearest free seat (or holding the seat already taken);
//! - [`stand_up`]: leaving the seat;
//! - [`turn`]: turning on the spot;
//! - [`lie`]: lying down on a bed or sofa, or on the floor;
//! - [`pick_up`]: walking to a small prop and taking it into the right hand;
//! - [`put_down`]: setting a held prop down on a surface or the floor ("puts the cup on the
//!   counter", "drops the cup");
//! - [`person`]: any of these done to or with another character ("walks to Tom", "sits next to
//!   Ben", "stands behind him", "talks to Anna");
//! - [`act`]: any other verb, an action in place over the idle or seated lower body, hands on the
//!   target's contacts (or a small prop picked up first and used in the hand).

pub(crate) mod act;
pub(crate) mod lie;
pub(crate) mod person;
pub(crate) mod pick_up;
pub(crate) mod put_down;
pub(crate) mod sit;
pub(crate) mod stand_up;
pub(crate) mod turn;
pub(crate) mod walk;

use super::builder::Builder;
use crate::motion::MotionLibrary;
use crate::ssg::Action;

/// What a verb does, decided once per action from its canonical tag.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Verb {
    /// "walk", "run" or any verb the library has a locomotion cycle for.
    Locomotion,
    /// "sit" or "sit_down".
    Sit,
    /// "stand_up" (and its synonyms "rise", "get up").
    StandUp,
    /// "stand" and its synonyms: stands up when seated, else a standing action.
    Stand,
    /// "lie", "lie down", "sleep": lying on the target when it has a seat, else on the floor.
    Lie,
    /// "turn": on the spot by this many radians (left +π/2, right −π/2, else about); seated, an
    /// action in place.
    Turn(f64),
    /// Any other verb: an action in place.
    Act,
}

/// One action of the timeline, read: its SSG action, canonical verb, kind, target and speed.
pub(crate) struct Step<'s> {
    /// The action as parsed (verb lemma, preposition, manner).
    pub action: &'s Action,
    /// The library's canonical tag for the verb (the lemma itself when the table lacks it).
    pub verb: String,
    pub kind: Verb,
    /// The scene object acted on.
    pub object: Option<usize>,
    /// Cruise speed (m/s) when the manner asks for a slow walk.
    pub speed: Option<f64>,
    /// Where the action puts its object: the preposition and the scene object ("on the counter").
    pub destination: Option<(String, usize)>,
}

impl Verb {
    /// The kind of a canonical verb tag; `manner` gives a turn's direction.
    pub fn of(verb: &str, manner: &[String], lib: &MotionLibrary) -> Verb {
        if lib.cycle(verb).is_some() || verb == "walk" || verb == "run" {
            return Verb::Locomotion;
        }
        match verb {
            "sit" | "sit_down" => Verb::Sit,
            "stand_up" => Verb::StandUp,
            "stand" => Verb::Stand,
            "lie" => Verb::Lie,
            "turn" => Verb::Turn(if manner.iter().any(|m| m == "right") {
                -std::f64::consts::FRAC_PI_2
            } else if manner.iter().any(|m| m == "left") {
                std::f64::consts::FRAC_PI_2
            } else {
                std::f64::consts::PI
            }),
            _ => Verb::Act,
        }
    }
}

impl<'s> Step<'s> {
    /// Reads an SSG action acting on `object`.
    pub fn read(action: &'s Action, object: Option<usize>, lib: &MotionLibrary, slow_speed: f64) -> Step<'s> {
        // A phrasal verb the parser split ("get" with the particle "up") is looked up whole
        // ("get_up" → stand_up) when the verb alone is not in the table.
        let phrasal =
            || action.manner.iter().find_map(|m| crate::motion::verbs::canonical(&format!("{}_{m}", action.verb)));
        let verb =
            crate::motion::verbs::canonical(&action.verb).or_else(phrasal).unwrap_or(action.verb.as_str()).to_string();
        let slow = action.manner.iter().any(|m| matches!(m.as_str(), "slowly" | "carefully" | "gently" | "lazily"));
        let kind = Verb::of(&verb, &action.manner, lib);
        Step { action, verb, kind, object, speed: slow.then_some(slow_speed), destination: None }
    }
}

/// Whether a step has motion: a kind with its own module, or a clip for its verb in `lib`.
pub(crate) fn plays(step: &Step, lib: &MotionLibrary) -> bool {
    step.kind != Verb::Act || has_motion(&step.verb, lib)
}

/// Whether a canonical verb tag has motion: locomotion, sitting, standing, turning and lying are
/// built; any other needs a clip in `lib`.
pub(crate) fn has_motion(tag: &str, lib: &MotionLibrary) -> bool {
    Verb::of(tag, &[], lib) != Verb::Act || matches!(tag, "idle") || lib.retrieve(tag).is_some()
}

impl Builder<'_> {
    /// Plays one action.
    pub fn play(&mut self, step: &Step) {
        match step.kind {
            Verb::Locomotion => self.walk_to(step),
            Verb::Sit => self.sit(step),
            Verb::StandUp => self.stand_up(),
            Verb::Stand if self.st.seated.is_some() || self.st.lying => self.stand_up(),
            Verb::Lie => self.lie(step),
            Verb::Turn(dh) if self.st.seated.is_none() && !self.st.lying => self.turn(dh, step.object),
            Verb::Stand | Verb::Turn(_) | Verb::Act => self.act(step),
        }
    }
}
