//! The scene database: authored rooms and their seeded variations are geometrically sound.

use inbetween_script::catalogue::builtin::builtin;
use inbetween_script::database::{authored_relations, derive_relations, holds, SceneDatabase};

#[test]
fn every_scene_is_sound() {
    let cat = builtin();
    for seed in [1, 2, 3, 42] {
        let db = SceneDatabase::builtin(&cat, 6, seed);
        assert_eq!(db.scenes.len(), 8 * 7);
        let problems: Vec<String> = db.scenes.iter().flat_map(|s| s.problems()).collect();
        assert!(problems.is_empty(), "seed {seed}:\n{}", problems.join("\n"));
        for s in &db.scenes {
            assert_eq!(s.ssg.objects.len(), s.placements.len());
            assert!(s.ssg.objects.len() >= 6, "{} has {} objects", s.name, s.ssg.objects.len());
            assert!(s.ssg.objects.iter().all(|o| cat.get(&o.category).is_some()));
            // The stored relation nodes are exactly what the placements imply.
            assert_eq!(s.ssg.relations, derive_relations(&s.placements), "{}", s.name);
        }
    }
}

#[test]
fn authored_rooms_have_their_intended_relations() {
    let cat = builtin();
    let db = SceneDatabase::builtin(&cat, 0, 0);
    let names: Vec<&str> = db.scenes.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(
        names,
        ["office", "bedroom", "livingroom", "gallery", "musicroom", "meetingroom", "workshop", "boxinggym"]
    );
    let intended = authored_relations(&cat);
    assert!(intended.len() >= 40);
    let mut kinds = std::collections::HashSet::new();
    for (scene, a, rel, b) in intended {
        let s = db.find(&scene).unwrap();
        assert!(
            holds(rel, &s.placements[a], &s.placements[b]),
            "{scene}: {} {} {}",
            s.ssg.objects[a].category,
            rel.phrase(),
            s.ssg.objects[b].category
        );
        kinds.insert(rel);
    }
    assert_eq!(kinds.len(), 8, "every relation kind is authored somewhere: {kinds:?}");
    for s in &db.scenes {
        assert!((8..=16).contains(&s.ssg.objects.len()), "{}: {}", s.name, s.ssg.objects.len());
    }
}

#[test]
fn same_seed_same_database_and_variations_vary() {
    let cat = builtin();
    let a = SceneDatabase::builtin(&cat, 4, 9);
    let b = SceneDatabase::builtin(&cat, 4, 9);
    assert_eq!(a.scenes, b.scenes);
    let c = SceneDatabase::builtin(&cat, 4, 10);
    assert_ne!(a.scenes, c.scenes);
    let differing = a.scenes.iter().filter(|s| s.name.contains("-v")).filter(|s| {
        let base = a.find(s.name.split("-v").next().unwrap()).unwrap();
        base.placements != s.placements || base.ssg.objects != s.ssg.objects
    });
    assert_eq!(differing.count(), 8 * 4);
}
