//! Template-action library (§3.2): procedural clips without files, retrieval by verb lemma and
//! synonyms, CMU tagging and loading on the real corpus when present.

use inbetween_script::motion::{walk_route_stats, ClipSource, MotionLibrary, Rig, WalkParams};

#[test]
fn procedural_library_needs_no_files_and_stands_on_the_floor() {
    let lib = MotionLibrary::procedural(0);
    let rig = Rig::standard();
    assert!(lib.clips.len() >= 14, "{} clips", lib.clips.len());
    for c in &lib.clips {
        assert_eq!(c.source, ClipSource::Procedural);
        assert_eq!(c.clip.skeleton(), &rig.skeleton, "{}", c.name);
        assert!((c.clip.fps() - 30.0).abs() < 1e-9);
        assert!(c.clip.num_frames() >= 30, "{}", c.name);
        let g = c.clip.globals();
        let low = g
            .iter()
            .map(|p| p.positions[rig.legs[0][2]].y.min(p.positions[rig.legs[1][2]].y))
            .fold(f64::INFINITY, f64::min);
        assert!((low - rig.ankle_height).abs() < 0.02, "{}: lowest ankle {low}", c.name);
        let head = g[0].positions[rig.head].y;
        assert!(head > 0.9 && head < 1.8, "{}: head at {head}", c.name);
    }
    for needed in [
        "walk", "run", "stand", "sit", "sit_down", "stand_up", "reach", "wave", "punch", "type", "call", "look",
        "think", "write",
    ] {
        assert!(lib.clips.iter().any(|c| c.has_tag(needed)), "no clip tagged {needed}");
    }
}

#[test]
fn retrieval_by_lemma_and_synonyms() {
    let lib = MotionLibrary::procedural(0);
    let name = |v: &str| lib.retrieve(v).map(|c| c.name.clone());
    assert_eq!(name("sit").as_deref(), Some("procedural sit"));
    assert_eq!(name("walk").as_deref(), Some("procedural walk cycle"));
    assert_eq!(name("punch").as_deref(), Some("procedural punch"));
    assert_eq!(name("box"), name("punch"));
    assert_eq!(name("jog"), name("run"));
    assert_eq!(name("phone"), name("call"));
    assert_eq!(name("talk"), name("call"));
    assert_eq!(name("play"), name("type"));
    assert_eq!(name("draw"), name("write"));
    assert_eq!(name("ponder"), name("think"));
    assert_eq!(name("stand").as_deref(), Some("procedural idle"));
    // Lemmatising is the caller's job, but common inflections still resolve.
    assert_eq!(name("sits"), name("sit"));
    assert_eq!(name("Walking"), name("walk"));
    assert_eq!(name("frobnicate"), None);
    assert_eq!(name(""), None);
    // A known verb with no clip in the procedural library.
    assert_eq!(name("kick"), None);
    assert!(lib.cycle("walk").unwrap().has_tag("cycle"));
    assert!(lib.cycle("run").unwrap().has_tag("run"));
}

#[test]
fn procedural_library_is_deterministic_per_seed() {
    let a = MotionLibrary::procedural(3);
    let b = MotionLibrary::procedural(3);
    let c = MotionLibrary::procedural(4);
    assert_eq!(a.clips, b.clips);
    assert_ne!(a.clips, c.clips);
}

#[test]
fn cmu_index_is_tagged_and_cgspeed_clips_load() {
    inbetween_io::data::with_shared_data("CMU mocap index", |data| {
        let dir = data.join("mocap/cmu");
        if !dir.join("index.tsv").is_file() {
            println!("skipped: no data at {}", dir.display());
            return;
        }
        let lib = MotionLibrary::with_cmu(&dir, 100).expect("index reads");
        assert!(lib.trials.len() > 2000, "{} trials", lib.trials.len());
        let tags = |id: &str| lib.trials.iter().find(|t| t.clip_id == id).map(|t| t.tags.clone()).unwrap_or_default();
        assert_eq!(tags("02_01"), vec!["walk"]);
        assert_eq!(tags("02_03"), vec!["run"]);
        assert_eq!(tags("02_05"), vec!["punch"]);
        assert_eq!(tags("01_01"), vec!["jump", "turn"]);
        assert!(tags("05_02").contains(&"dance".to_string()));
        assert!(tags("01_08").contains(&"sit".to_string()));
        let tagged = lib.trials.iter().filter(|t| !t.tags.is_empty()).count();
        println!(
            "CMU: {} trials, {tagged} tagged, {} clips loaded in {:.2} s, {} skipped",
            lib.trials.len(),
            lib.clips.iter().filter(|c| c.is_captured()).count(),
            lib.load_seconds,
            lib.skipped.len()
        );
        assert!(tagged * 2 > lib.trials.len());
        let rig = Rig::standard();
        let captured: Vec<_> = lib.clips.iter().filter(|c| c.is_captured()).collect();
        assert!(!captured.is_empty());
        for c in &captured {
            assert_eq!(c.clip.skeleton(), &rig.skeleton);
            let g = c.clip.globals();
            // Grounded: the 5th percentile of the lowest toe is at the floor (uneven-terrain and
            // climbing trials go below and above it elsewhere).
            let mut toes: Vec<f64> =
                g.iter().map(|p| p.positions[rig.legs[0][3]].y.min(p.positions[rig.legs[1][3]].y)).collect();
            toes.sort_by(f64::total_cmp);
            let toe = toes[toes.len() / 20];
            assert!(toe.abs() < 0.03, "{}: 5th-percentile toe {toe}", c.name);
            let head = g.iter().map(|p| p.positions[rig.head].y).sum::<f64>() / g.len() as f64;
            assert!(head > 1.1 && head < 1.7, "{}: head {head}", c.name);
            // Starts at the origin.
            let r0 = g[0].positions[0];
            assert!(r0.x.abs() < 1e-9 && r0.z.abs() < 1e-9);
        }
        // Real clips win over procedural ones for their primary action.
        if lib.trials.iter().any(|t| t.clip_id == "131_01" && t.cgspeed_bvh().is_some()) {
            assert!(lib.retrieve("walk").unwrap().is_captured());
        }
        // The iClone/Character Creator conversions retarget too: a CMU walk walks forward.
        if let Some(walk) = lib.clips.iter().find(|c| c.name.starts_with("cmu 02_01")) {
            let g = walk.clip.globals();
            let end = g.last().unwrap().positions[0];
            assert!(end.z > 2.0 && end.x.abs() < 1.0, "02_01 ends at {end:?}");
            let hips = g.iter().map(|p| p.positions[0].y).sum::<f64>() / g.len() as f64;
            assert!(hips > 0.8 && hips < 1.0, "hips at {hips}");
            assert_eq!(lib.retrieve("walk").unwrap().name, walk.name);
            assert!(lib.retrieve("punch").unwrap().is_captured());
            // A playground climb that mentions sitting does not displace the seated clip.
            assert_eq!(lib.retrieve("sit").unwrap().name, "procedural sit");
        }
        // Locomotion still uses a cycle.
        assert!(lib.cycle("walk").unwrap().has_tag("cycle"));
        let one = MotionLibrary::with_cmu(&dir, 1).unwrap();
        assert_eq!(one.clips.iter().filter(|c| c.is_captured()).count(), 1);
        let again = MotionLibrary::with_cmu(&dir, 1).unwrap();
        assert_eq!(one.clips, again.clips);
    });
}

#[test]
fn kenney_animation_names_are_tagged() {
    use inbetween_script::motion::kenney::tags_of_name;
    assert_eq!(tags_of_name("attack-kick-right"), vec!["kick"]);
    assert_eq!(tags_of_name("attack-melee-left"), vec!["punch"]);
    assert_eq!(tags_of_name("sprint"), vec!["run"]);
    assert_eq!(tags_of_name("pick-up"), vec!["reach"]);
    assert!(tags_of_name("static").is_empty());
    assert!(tags_of_name("wheelchair-move-left").is_empty());
}

#[test]
fn kenney_characters_add_clips_when_present() {
    inbetween_io::data::with_shared_data("Kenney blocky characters", |data| {
        let dir = data.join("assets/kenney_blocky_characters");
        if !dir.is_dir() {
            println!("skipped: no data at {}", dir.display());
            return;
        }
        let mut lib = MotionLibrary::procedural(0);
        let added = lib.add_kenney(&dir).expect("glb files read");
        println!(
            "Kenney: {added} clips in {:.3} s: {:?}",
            lib.load_seconds,
            lib.clips.iter().filter(|c| c.has_tag("kenney")).map(|c| &c.name).collect::<Vec<_>>()
        );
        assert!(added >= 5);
        // The procedural library has no kick: the Kenney one fills the gap; procedural clips
        // still win where both exist.
        let kick = lib.retrieve("kick").expect("a kick clip");
        assert!(matches!(kick.source, ClipSource::Kenney { .. }));
        assert_eq!(lib.retrieve("walk").unwrap().source, ClipSource::Procedural);
        // Orientation: the right kick swings the right foot forward (+Z), above the floor.
        let rig = Rig::standard();
        let g = kick.clip.globals();
        let (mut fwd, mut up): (f64, f64) = (0.0, 0.0);
        let side = if kick.name.contains("right") { 1 } else { 0 };
        for p in &g {
            let foot = p.positions[rig.legs[side][2]];
            fwd = fwd.max(foot.z - p.positions[0].z);
            up = up.max(foot.y);
        }
        assert!(fwd > 0.25 && up > 0.2, "kick reaches {fwd} forward, {up} up");
        let all = MotionLibrary::from_shared(10);
        assert!(all.clips.len() >= lib.clips.len());
    });
}

#[test]
fn captured_walks_give_locomotion_its_cycle() {
    inbetween_io::data::with_shared_data("CMU mocap walks", |data| {
        let dir = data.join("mocap/cmu");
        if !dir.join("iclone_cc/002_01.bvh").is_file() {
            println!("skipped: no data at {}", dir.join("iclone_cc/002_01.bvh").display());
            return;
        }
        let lib = MotionLibrary::with_cmu(&dir, 40).expect("index reads");
        let cycle = lib.cycle("walk").expect("a walk cycle");
        assert!(cycle.is_captured(), "{}", cycle.name);
        assert!(cycle.has_tag("cycle") && cycle.has_tag("cmu"));
        let seconds = cycle.clip.num_frames() as f64 * cycle.clip.frame_time();
        assert!((0.8..=1.6).contains(&seconds), "{}: {seconds} s", cycle.name);
        // Walking an L-shaped route on captured steps: locking keeps skate low.
        let route = [[0.0, 0.0], [0.0, 3.0], [2.5, 3.0]];
        let (_, captured) = walk_route_stats(&route, &lib, &WalkParams::default());
        let (_, procedural) = walk_route_stats(&route, &MotionLibrary::procedural(0), &WalkParams::default());
        println!(
            "{}: {seconds:.2} s; skate {:.1} → {:.1} cm/s (procedural cycle {:.1} → {:.1})",
            cycle.name, captured.skate_before, captured.skate_after, procedural.skate_before, procedural.skate_after
        );
        assert!(captured.skate_after < 10.0, "{captured:?}");
        assert!(captured.max_route_error < 0.3, "{captured:?}");
    });
}
