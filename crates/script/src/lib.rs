//! Text to animation (Zhang et al., "Write-An-Animation: High-level Text-based Animation Editing
//! with Character-Scene Interaction", Pacific Graphics 2021).
//!
//! The folders follow the paper's pipeline (Fig. 2). Part 1, text → semantic scene graph →
//! furnished scene (§3.2, §4.1):
//! - [`sentences`]: the user's text split into scene descriptions (ending in `$`), character
//!   directions and verbal commands (§3.2);
//! - [`parse`]: tokenising, POS tagging, lemmatising and the rules that turn tags into a
//!   [`ssg::Ssg`], the semantic scene graph (the paper uses CoreNLP dependencies; we use tags +
//!   rules, see the crate README);
//! - [`catalogue`]: object categories with sizes, contact points and synonyms;
//! - [`database`]: the scene database, every scene saved as an SSG with placements (§3.2);
//! - [`matching`]: SSG matching, relation-first (Algorithm 1) and the LDS object-first baseline;
//! - [`layout`]: placing objects so relations hold without interpenetration, inside the room,
//!   reachable;
//! - [`compose`]: matching + layout → a furnished [`scene::Scene`]; [`scene_session`] re-solves
//!   only what an edit touches;
//! - [`semantic`] (and `embed`, feature `embeddings`): words outside the synonym tables read
//!   through sentence embeddings.
//!
//! Part 2, characters acting in the scene (§3.2 template actions, §4.2 motion synthesis, §4.3
//! joint optimisation):
//! - [`motion`]: the motion library (procedural clips, CMU and Character Creator BVH retargeted
//!   onto the common rig, Kenney animations), walking a route with foot locking, upper/lower-body
//!   blending, two-bone IK;
//! - [`animate`]: each character's timeline, one module per action (walk, sit, stand up, turn,
//!   pick up, act on an object), several characters kept apart, camera shots;
//! - [`optimize`]: Algorithm 2, the collision and contact costs (Eq. 1–3) minimised by annealing
//!   over object positions and heights (Eq. 4);
//! - [`story_session`]: the editing loop of part 2, re-animating only the characters an edit touches and
//!   re-optimising only their objects (above both [`animate`] and [`optimize`]).
//!
//! Both parts write through [`output`] (scene JSON, glTF with boxes, meshes, animated skeletons
//! or skinned characters, BVH, PNG and GIF previews); [`jobs`] runs them for the front ends
//! ([`jobs::SceneJob`], [`jobs::RunJob`]), [`bench`] measures them, [`demo`] and [`builtin_scripts`] hold the
//! built-in texts.
//!
//! Units: metres, Y up, the floor at y = 0 (glTF's convention).

pub mod animate;
pub mod bench;
pub mod builtin_scripts;
pub mod catalogue;
pub mod compose;
pub mod database;
pub mod demo;
#[cfg(feature = "embeddings")]
pub mod embed;
pub mod error;
pub mod fidelity;
pub mod invariants;
pub mod jobs;
pub mod layout;
pub mod limits;
pub mod matching;
pub mod motion;
pub mod optimize;
pub mod output;
pub mod parse;
pub mod scene;
pub mod scene_session;
pub mod semantic;
pub mod sentences;
pub mod ssg;
pub mod story_session;

pub use error::ScriptError;
