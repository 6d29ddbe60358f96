//! Text to animation (Zhang et al., "Write-An-Animation: High-level Text-based Animation Editing
//! with Character-Scene Interaction", Pacific Graphics 2021), part 1: text → semantic scene graph
//! → furnished scene (§3.2, §4.1).
//!
//! The folders follow the paper's pipeline (Fig. 2):
//! - [`script`]: the user's text split into scene descriptions (ending in `$`), character
//!   directions and verbal commands (§3.2);
//! - [`parse`]: tokenising, POS tagging, lemmatising and the rules that turn tags into a
//!   [`ssg::Ssg`], the semantic scene graph (the paper uses CoreNLP dependencies; we use tags +
//!   rules, see the crate README);
//! - [`catalogue`]: object categories with sizes, contact points and synonyms;
//! - [`database`]: the scene database, every scene saved as an SSG with placements (§3.2);
//! - [`matching`]: SSG matching, relation-first (Algorithm 1) and the LDS object-first baseline;
//! - [`layout`]: placing objects so relations hold without interpenetration, inside the room,
//!   reachable;
//! - [`compose`]: matching + layout → a furnished [`scene::Scene`]; [`session`] re-solves only
//!   what an edit touches;
//! - [`output`]: JSON, glTF, top-down and perspective PNG previews.
//!
//! Units: metres, Y up, the floor at y = 0 (glTF's convention).

pub mod animate;
pub mod bench;
pub mod catalogue;
pub mod compose;
pub mod database;
pub mod demo;
#[cfg(feature = "embeddings")]
pub mod embed;
pub mod error;
pub mod job;
pub mod layout;
pub mod matching;
pub mod motion;
pub mod optimize;
pub mod output;
pub mod parse;
pub mod scene;
pub mod script;
pub mod semantic;
pub mod session;
pub mod ssg;
pub mod stories;

pub use error::ScriptError;
