//! Built-in scripts: the paper's figure texts as written (quirks included: `\$`, `$.`, the `".`
//! that stands for `$`, a sentence broken over lines), a demo story, and a short film script we
//! wrote in the paper's style for a public-domain film (§5: "texts from public film scripts").
//!
//! The extracted paper text does not say which caption text belongs to which figure panel beyond
//! Fig. 1; the grouping of the Fig. 5–7 texts below follows their content (iterative scenes with
//! Susan and Tom, film-like lines, per-scene actions).

/// Fig. 1: the interface example.
pub const FIG1: &str = "'Eve walks to the house
\"In the room, an organized office desk is near a bed\\$.\"
\"camera front\"
\"Eve sits on the couch. and sings with the microphone\"
";

/// Fig. 5: iterative creation with customised text (gallery and meeting room).
pub const FIG5: &str =
    "\"In a gallery there is a horsesculpture and a oilpainting\\$. There is also a sculpture and a picture\\$.\"
\"There is a blackboard in a meetingroom\\$. There is an arranged table in the meetingroom\\$......\"
\"Susan walks to the oilpainting. Susan stands in the front of oilpainting and is looking at it.\"
\"Susan walks to the picture and plays with the phone.\"
\"Susan walks to the horsesculpture. Susan is thinking before the horsesculpture.\"
\"Tom sits on a modernchair. Tom sits and calls with phone. Tom sits madly. Tom stands.\"
\"Tom turns right. Tom stands and writes on the blackboard.\"
";

/// Fig. 6: the film-script line of the extracted figure text.
pub const FIG6: &str = "\"The man walks unbelievably to the road.\"
";

/// Fig. 7: actions in different scenes (boxing gym, workshop, music room).
pub const FIG7: &str =
    "\"There is a boxing ring above which a boxingbag hangs\". There is a stool and a desk.\". There is a bottle\"
\"There is an organized working shop\\$. A hammer and a wood is on the table\\$. A shelf and a sofa are in the front\"
\"There is a music room\\$. A computer and a recorder are on a desk\\$. There is a piano and a chair in front\"
\"Worker is serving the wood
\"Mary is punching boxingbag.\"
\"Mary is drinking soda.\"
\"Worker is sawing the wood.\"
\"Anny walks to the recorder

and pushes the record button.\"
\"Worker is hammering the nail into the wood.\"
\"Worker draws the design diagram.\"
\"Anny sits on the chair and sings with microphone.\"
\"Anny stands and is listening to music with the headphones.\"
";

/// The Fig. 5 and Fig. 7 texts hold several scenes each; composed as one they would crowd a single
/// room. These are the same lines, one scene per text, with the characters that act in it.
pub const FIG5_GALLERY: &str =
    "\"In a gallery there is a horsesculpture and a oilpainting\\$. There is also a sculpture and a picture\\$.\"
\"Susan walks to the oilpainting. Susan stands in the front of oilpainting and is looking at it.\"
\"Susan walks to the picture and plays with the phone.\"
\"Susan walks to the horsesculpture. Susan is thinking before the horsesculpture.\"
";

/// Fig. 5, the meeting-room scene.
pub const FIG5_MEETING_ROOM: &str =
    "\"There is a blackboard in a meetingroom\\$. There is an arranged table in the meetingroom\\$......\"
\"Tom sits on a modernchair. Tom sits and calls with phone. Tom sits madly. Tom stands.\"
\"Tom turns right. Tom stands and writes on the blackboard.\"
";

/// Fig. 7, the boxing gym.
pub const FIG7_BOXING: &str =
    "\"There is a boxing ring above which a boxingbag hangs\". There is a stool and a desk.\". There is a bottle\"
\"Mary is punching boxingbag.\"
\"Mary is drinking soda.\"
";

/// Fig. 7, the workshop.
pub const FIG7_WORKSHOP: &str = "\"There is an organized working shop\\$. A hammer and a wood is on the table\\$. A shelf and a sofa are in the front\"
\"Worker is serving the wood
\"Worker is sawing the wood.\"
\"Worker is hammering the nail into the wood.\"
\"Worker draws the design diagram.\"
";

/// Fig. 7, the music room.
pub const FIG7_MUSIC_ROOM: &str =
    "\"There is a music room\\$. A computer and a recorder are on a desk\\$. There is a piano and a chair in front\"
\"Anny walks to the recorder

and pushes the record button.\"
\"Anny sits on the chair and sings with microphone.\"
\"Anny stands and is listening to music with the headphones.\"
";

/// A short demo: an office with a living-room corner, a camera command, two characters.
pub const DEMO: &str = "# Demo script: scene lines end in $, the rest directs the characters.
In the office, an organized desk is near a bookshelf$
A laptop and a lamp are on the desk$
A sofa is in front of a table, and a chair is next to the desk$
camera front
Eve walks to the desk and sits on the chair.
Eve types on the laptop.
Tom walks slowly to the sofa and sits on it.
";

/// The demo story at `k` times its size, for scaling runs: the demo's scene lines once, then its
/// three direction sentences (five actions) `k` times in a row (Eve sits down, types, and walks
/// back to the desk again; Tom returns to the sofa each time).
pub fn scaled_demo(k: usize) -> String {
    let (scene, directions): (Vec<&str>, Vec<&str>) =
        DEMO.lines().filter(|l| !l.starts_with('#')).partition(|l| l.ends_with('$') || l.starts_with("camera"));
    let mut text = scene.join("\n") + "\n";
    for _ in 0..k {
        text.push_str(&directions.join("\n"));
        text.push('\n');
    }
    text
}

/// Character actions (verbs) in one repetition of the demo's directions in [`scaled_demo`].
pub const DEMO_ACTIONS: usize = 5;

/// Limits that let [`scaled_demo`]`(k)` through (the defaults refuse a story of 100× the demo, on
/// purpose): 100 sentences, 1 000 words, 100 actions and 120 s of animation per repetition.
pub fn scaled_demo_limits(k: usize) -> crate::limits::ScriptLimits {
    let k = k.max(1);
    crate::limits::ScriptLimits {
        max_sentences: 100 * k,
        max_words: 1000 * k,
        max_actions: 100 * k,
        max_animation_s: 120.0 * k as f64,
        ..Default::default()
    }
}

/// A few lines in the paper's style for "Night of the Living Dead" (1968, public domain): the
/// farmhouse living room. Our own wording: scene and actions only, no dialogue.
pub const NIGHT_OF_THE_LIVING_DEAD: &str =
    "# Night of the Living Dead (1968), the farmhouse: our own lines, no dialogue.
In the living room, an old sofa is near a table$
A phone is on the table$
There is a shelf behind the sofa and a lamp is on the shelf$
time night
weather rainy
Barbra walks to the sofa and sits on it.
Ben walks quickly to the table and picks up the phone.
Ben nails the wood onto the door.
camera close
Barbra stands and looks madly at the window.
";

/// Issue 27's bedroom: a chair in front of the desk is tucked at it; Tom pulls it out to sit
/// and pushes it back in when he gets up.
pub const BEDROOM_DESK: &str =
    "# A bedroom desk: the chair is tucked at the desk, pulled out to sit on and pushed back.
In the bedroom, a bed is next to a wardrobe$
A desk is near the window$
A chair is in front of the desk$
camera front
Tom walks to the desk and sits on the chair.
Tom gets up and walks to the bed.
";

/// All built-in texts as (name, text).
pub fn all() -> Vec<(&'static str, &'static str)> {
    vec![
        ("fig1", FIG1),
        ("fig5-gallery", FIG5_GALLERY),
        ("fig5-meetingroom", FIG5_MEETING_ROOM),
        ("fig6", FIG6),
        ("fig7-boxing", FIG7_BOXING),
        ("fig7-workshop", FIG7_WORKSHOP),
        ("fig7-musicroom", FIG7_MUSIC_ROOM),
        ("demo", DEMO),
        ("night-of-the-living-dead", NIGHT_OF_THE_LIVING_DEAD),
        ("bedroom-desk", BEDROOM_DESK),
    ]
}

/// Room kinds, furniture, small things, names and directions [`random_story`] draws from (all of
/// them words the parser and the motion library know).
const RANDOM_ROOMS: &[&str] = &["office", "bedroom", "living room", "room", "kitchen"];
const RANDOM_FURNITURE: &[&str] =
    &["desk", "table", "chair", "sofa", "bed", "wardrobe", "bookcase", "armchair", "stool", "cabinet"];
const RANDOM_SMALL: &[&str] = &["cup", "book", "lamp", "laptop", "phone", "vase", "bottle"];
const RANDOM_SEATS: &[&str] = &["chair", "sofa", "armchair", "stool", "bed"];
const RANDOM_RELATIONS: &[&str] = &["near", "next to", "in front of", "behind"];
const RANDOM_NAMES: &[&str] = &["Tom", "Eve", "Anna", "Ben"];
const RANDOM_VIEWS: &[&str] = &["front", "back", "left", "right", "close", "wide", "top"];

/// A random story (deterministic in `seed`) in the style of the built-in texts: a room with two to
/// four pieces of furniture related to each other, a small thing on one of them, a camera
/// command, and one or two characters walking, sitting, lying down, standing up, picking things
/// up and acting on them. The property tests of issue 27 check every invariant on such stories.
pub fn random_story(seed: u64) -> String {
    use rand::seq::IndexedRandom;
    use rand::Rng;
    let mut rng = inbetween_core::seed::rng(seed);
    fn pick<R: Rng>(rng: &mut R, from: &[&'static str]) -> &'static str {
        from.choose(rng).expect("non-empty")
    }
    let mut lines = Vec::new();
    let n = rng.random_range(2..=4usize);
    let mut furniture: Vec<&'static str> = Vec::new();
    while furniture.len() < n {
        let f = pick(&mut rng, RANDOM_FURNITURE);
        if !furniture.contains(&f) {
            furniture.push(f);
        }
    }
    let a = |w: &str| if w.starts_with(['a', 'e', 'i', 'o', 'u']) { format!("an {w}") } else { format!("a {w}") };
    let room = pick(&mut rng, RANDOM_ROOMS);
    lines.push(format!(
        "In the {room}, {} is {} {}$",
        a(furniture[0]),
        pick(&mut rng, RANDOM_RELATIONS),
        a(furniture[1])
    ));
    for k in 2..furniture.len() {
        let anchor = furniture[rng.random_range(0..k)];
        let what = a(furniture[k]);
        lines.push(format!(
            "{}{} is {} the {anchor}$",
            what[..1].to_uppercase(),
            &what[1..],
            pick(&mut rng, RANDOM_RELATIONS)
        ));
    }
    let surfaces: Vec<&'static str> =
        furniture.iter().copied().filter(|f| matches!(*f, "desk" | "table" | "cabinet")).collect();
    let small = pick(&mut rng, RANDOM_SMALL);
    if let Some(s) = surfaces.choose(&mut rng) {
        let what = a(small);
        lines.push(format!("{}{} is on the {s}$", what[..1].to_uppercase(), &what[1..]));
    }
    lines.push(format!("camera {}", pick(&mut rng, RANDOM_VIEWS)));
    let characters = rng.random_range(1..=2usize);
    let mut seats: Vec<&'static str> = furniture.iter().copied().filter(|f| RANDOM_SEATS.contains(f)).collect();
    // Who holds the small prop.
    let mut held: Option<usize> = None;
    for c in 0..characters {
        let name = RANDOM_NAMES[(seed as usize + c) % RANDOM_NAMES.len()];
        let mut seated = false;
        for _ in 0..rng.random_range(1..=3usize) {
            let target = pick(&mut rng, &furniture);
            let line = match rng.random_range(0..9u32) {
                0 | 1 if !seated => format!("{name} walks to the {target}."),
                2 if !seated && !seats.is_empty() => {
                    seated = true;
                    // One character per seat.
                    let seat = seats.remove(rng.random_range(0..seats.len()));
                    format!("{name} walks to the {seat} and sits on it.")
                }
                3 if seated => {
                    seated = false;
                    format!("{name} gets up.")
                }
                // A second pick-up of the prop in hand puts it down instead.
                4 if held == Some(c) => {
                    held = None;
                    format!("{name} puts the {small} on the {}.", surfaces[rng.random_range(0..surfaces.len())])
                }
                4 if !surfaces.is_empty() && held.is_none() => {
                    held = Some(c);
                    format!("{name} picks up the {small}.")
                }
                5 => format!("{name} looks at the {target}."),
                6 if !seated => format!("{name} runs to the {target}."),
                7 if !seated => match furniture.iter().find(|f| matches!(**f, "bed" | "sofa")) {
                    Some(bed) => {
                        seated = true;
                        format!("{name} lies down on the {bed}.")
                    }
                    None => format!("{name} waves."),
                },
                _ => format!("{name} {}.", pick(&mut rng, &["waves", "thinks", "points at the window", "turns left"])),
            };
            lines.push(line);
        }
    }
    lines.join("\n") + "\n"
}

/// The story with one object added to its first scene sentence ("… near a bookshelf$" →
/// "… near a bookshelf and a plant$"), the kind of edit users make while iterating.
pub fn edit_one_sentence(text: &str) -> String {
    let mut done = false;
    let mut lines: Vec<String> = Vec::new();
    for line in text.lines() {
        match line.find('$') {
            Some(i) if !done && !line.trim_start().starts_with('#') => {
                lines.push(format!("{} and a plant{}", &line[..i], &line[i..]));
                done = true;
            }
            _ => lines.push(line.to_string()),
        }
    }
    if !done {
        lines.push("There is a plant$".into());
    }
    lines.join("\n") + "\n"
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scaled_demo_repeats_the_directions_not_the_scene() {
        let one = scaled_demo(1);
        let three = scaled_demo(3);
        let count = |t: &str, s: &str| t.matches(s).count();
        assert_eq!(count(&three, "organized desk"), 1);
        assert_eq!(count(&three, "camera front"), 1);
        assert_eq!(count(&three, "Eve types on the laptop."), 3);
        assert_eq!(crate::sentences::split(&three).len() - crate::sentences::split(&one).len(), 6);
        assert_eq!(crate::sentences::split(&one).len(), crate::sentences::split(DEMO).len());
    }

    /// 100× the demo is over the default limits and within its own; its actions are the count the
    /// scale table gives.
    #[test]
    fn the_scaled_demo_passes_its_own_limits_only() {
        let cat = crate::catalogue::builtin::builtin();
        let big = scaled_demo(100);
        let e = crate::limits::ScriptLimits::default().check_text(&big, "big", &cat).unwrap_err();
        assert!(["max_sentences", "max_words", "max_actions"].contains(&e.field), "{e}");
        scaled_demo_limits(100).check_text(&big, "big", &cat).unwrap();
        let verbs = |t: &str| {
            let parsed = crate::parse::parse_script(t, &cat);
            parsed.sentences.iter().flat_map(|s| &s.ssg.characters).map(|c| c.actions.len()).sum::<usize>()
        };
        assert_eq!(verbs(&scaled_demo(2)) - verbs(&scaled_demo(1)), DEMO_ACTIONS);
    }
}
