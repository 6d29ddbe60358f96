//! Layout: every relation placed and holding, no overlaps, pinned poses kept, overfull rooms drop
//! items with reasons, determinism.

use inbetween_script::catalogue::Support;
use inbetween_script::database::Placement;
use inbetween_script::layout::{
    check, relation_holds, solve, strictly_holds, LayoutConstraint, LayoutItem, LayoutProblem,
};
use inbetween_script::scene::{Origin, PlacedObject, Room};
use inbetween_script::ssg::Relation;
use proptest::prelude::*;

fn room(w: f32, d: f32) -> Room {
    Room { name: "room".into(), width: w, depth: d, height: 2.8 }
}

fn item(label: &str, size: [f32; 3], support: Support, surface: bool) -> LayoutItem {
    LayoutItem {
        label: label.into(),
        category: label.split(' ').next().unwrap().into(),
        attributes: vec![],
        size,
        support,
        surface,
        origin: Origin::Script { sentence: 0, node: 0 },
        hint: None,
        pinned: None,
        seat: false,
    }
}

fn desk() -> LayoutItem {
    item("desk", [1.4, 0.75, 0.7], Support::Floor, true)
}
fn table() -> LayoutItem {
    item("table", [1.2, 0.75, 0.8], Support::Floor, true)
}
fn chair() -> LayoutItem {
    LayoutItem { seat: true, ..item("chair", [0.5, 0.9, 0.5], Support::Floor, false) }
}
fn stool() -> LayoutItem {
    LayoutItem { seat: true, ..item("stool", [0.4, 0.45, 0.4], Support::Floor, false) }
}
fn lamp() -> LayoutItem {
    item("lamp", [0.2, 0.45, 0.2], Support::Surface, false)
}
fn painting() -> LayoutItem {
    item("painting", [0.9, 0.7, 0.05], Support::Wall, false)
}
fn sofa() -> LayoutItem {
    item("sofa", [2.0, 0.85, 0.9], Support::Floor, false)
}
fn bag() -> LayoutItem {
    item("bag", [0.4, 1.1, 0.4], Support::Ceiling, false)
}
fn bed() -> LayoutItem {
    item("bed", [1.6, 0.5, 2.1], Support::Floor, false)
}
fn ring() -> LayoutItem {
    item("ring", [3.0, 0.1, 3.0], Support::Floor, false)
}

fn problem(items: Vec<LayoutItem>, rels: &[(Relation, usize, usize)]) -> LayoutProblem {
    LayoutProblem {
        room: room(5.0, 4.0),
        items,
        relations: rels
            .iter()
            .map(|&(relation, active, anchor)| LayoutConstraint { relation, active, anchor })
            .collect(),
        places: vec![],
    }
}

fn assert_clean(p: &LayoutProblem, seed: u64) -> inbetween_script::layout::LayoutOutcome {
    let out = solve(p, seed);
    assert!(out.dropped.is_empty(), "dropped {:?}", out.dropped);
    assert_eq!(out.violations.total(), 0, "{:?}\n{:#?}", out.violations, out.objects);
    for c in &p.relations {
        let (a, b) = (out.placed[c.active].unwrap(), out.placed[c.anchor].unwrap());
        assert!(relation_holds(c.relation, &out.objects[a], &out.objects[b]), "{:?} fails", c.relation);
    }
    out
}

#[test]
fn every_relation_is_placed_and_holds() {
    let cases: Vec<(Relation, LayoutItem, LayoutItem)> = vec![
        (Relation::On, lamp(), desk()),
        (Relation::Near, chair(), bed()),
        (Relation::InFrontOf, chair(), desk()),
        (Relation::NextTo, chair(), sofa()),
        (Relation::Under, stool(), table()),
        (Relation::Above, painting(), sofa()),
        (Relation::Above, bag(), ring()),
        (Relation::In, chair(), ring()),
        (Relation::Behind, chair(), sofa()),
    ];
    for (rel, active, anchor) in cases {
        for seed in 0..5 {
            let p = problem(vec![anchor.clone(), active.clone()], &[(rel, 1, 0)]);
            let out = solve(&p, seed);
            assert!(
                out.dropped.is_empty() && out.violations.total() == 0,
                "{rel:?} seed {seed}: {:?} {:?}\n{:#?}",
                out.dropped,
                out.violations,
                out.objects
            );
            let out = assert_clean(&p, seed);
            assert!(
                strictly_holds(rel, &out.objects[1], &out.objects[0]),
                "{rel:?} seed {seed}: not tidy\n{:#?}",
                out.objects
            );
            if rel == Relation::On {
                assert_eq!(out.objects[1].support, Some(0));
            }
        }
    }
}

#[test]
fn facing_and_heights_follow_the_conventions() {
    let p = problem(vec![desk(), chair(), painting(), bag()], &[(Relation::InFrontOf, 1, 0)]);
    let out = assert_clean(&p, 3);
    let (d, c) = (&out.objects[0], &out.objects[1]);
    // The chair faces the desk: its forward points from it towards the desk.
    let f = [c.yaw.sin(), c.yaw.cos()];
    let to = [d.position[0] - c.position[0], d.position[2] - c.position[2]];
    assert!(f[0] * to[0] + f[1] * to[1] > 0.0, "chair faces away");
    let pt = &out.objects[2];
    assert!((pt.position[1] + pt.size[1] / 2.0 - 1.5).abs() < 1e-3, "painting centred at 1.5 m");
    let [hx, hz] = pt.half_extents_xz();
    let touches = pt.position[0] - hx < 0.01
        || pt.position[2] - hz < 0.01
        || pt.position[0] + hx > 4.99
        || pt.position[2] + hz > 3.99;
    assert!(touches, "painting on a wall: {:?}", pt.position);
    let bag = &out.objects[3];
    assert!((bag.top() - 2.8).abs() < 1e-3, "hangs from the ceiling");
}

#[test]
fn under_a_too_low_table_is_unmet_not_a_panic() {
    let low = item("table", [1.2, 0.3, 0.8], Support::Floor, true);
    let p = problem(vec![low, stool()], &[(Relation::Under, 1, 0)]);
    let out = solve(&p, 1);
    assert!(out.dropped.is_empty());
    assert_eq!(out.violations.unmet, vec![0]);
    assert!(out.violations.overlaps.is_empty());
}

#[test]
fn surface_objects_go_on_a_surface_when_there_is_one() {
    let p = problem(vec![lamp(), desk(), item("cup", [0.1, 0.1, 0.1], Support::Surface, false)], &[]);
    let out = assert_clean(&p, 7);
    let desk_idx = out.placed[1].unwrap();
    assert_eq!(out.objects[out.placed[0].unwrap()].support, Some(desk_idx));
    assert_eq!(out.objects[out.placed[2].unwrap()].support, Some(desk_idx));
    // Alone, a lamp stands on the floor.
    let out = assert_clean(&problem(vec![lamp()], &[]), 7);
    assert_eq!(out.objects[0].position[1], 0.0);
}

#[test]
fn pinned_objects_stay_exactly_and_hints_are_honoured() {
    let mut d = desk();
    d.pinned = Some(([3.0, 0.0, 0.35], 0.0));
    let mut b = bed();
    b.hint = Some(Placement { position: [0.8, 0.0, 1.05], yaw: 0.0, size: b.size });
    let p = problem(vec![d, chair(), b], &[(Relation::InFrontOf, 1, 0)]);
    for seed in 0..4 {
        let out = assert_clean(&p, seed);
        assert_eq!(out.objects[0].position, [3.0, 0.0, 0.35]);
        assert_eq!(out.objects[0].yaw, 0.0);
        assert_eq!(out.objects[2].position, [0.8, 0.0, 1.05], "valid hint kept");
    }
}

#[test]
fn an_overfull_room_drops_items_with_reasons() {
    let mut items = vec![];
    for k in 0..12 {
        items.push(item(&format!("piano {k}"), [1.6, 1.0, 1.5], Support::Floor, false));
    }
    let p = problem(items, &[]);
    let out = solve(&p, 0);
    assert!(!out.dropped.is_empty());
    assert_eq!(out.objects.len() + out.dropped.len(), 12);
    let (k, why) = &out.dropped[0];
    assert!(
        why.contains(&format!("'piano {k}'"))
            && why.contains("5.0 × 4.0 m room")
            && why.contains("no free floor space"),
        "{why}"
    );
    assert!(
        out.violations.overlaps.is_empty()
            && out.violations.outside.is_empty()
            && out.violations.unreachable.is_empty()
    );
    // An object bigger than the room.
    let out = solve(&problem(vec![item("stage", [6.0, 1.0, 6.0], Support::Floor, false)], &[]), 0);
    assert_eq!(out.dropped.len(), 1);
    assert!(out.placed[0].is_none());
}

#[test]
fn same_seed_same_layout() {
    let p = problem(
        vec![desk(), chair(), lamp(), painting(), sofa(), table(), stool()],
        &[(Relation::InFrontOf, 1, 0), (Relation::On, 2, 0), (Relation::Above, 3, 4), (Relation::Under, 6, 5)],
    );
    let a = assert_clean(&p, 11);
    assert_eq!(a, solve(&p, 11));
}

#[test]
fn check_reports_each_kind_of_violation() {
    let r = room(5.0, 4.0);
    let obj = |label: &str, position: [f32; 3], size: [f32; 3]| PlacedObject {
        label: label.into(),
        category: label.into(),
        attributes: vec![],
        position,
        yaw: 0.0,
        size,
        support: None,
        origin: Origin::Script { sentence: 0, node: 0 },
    };
    let objs = vec![
        obj("a", [1.0, 0.0, 1.0], [1.0, 1.0, 1.0]),
        obj("b", [1.3, 0.0, 1.2], [1.0, 1.0, 1.0]),
        obj("c", [4.9, 0.0, 2.0], [1.0, 1.0, 1.0]),
    ];
    let v = check(&r, &objs, &[(Relation::Near, 2, 0)]);
    assert_eq!(v.overlaps, vec![(0, 1)]);
    assert_eq!(v.outside, vec![2]);
    assert_eq!(v.unmet, vec![0]);
    // Stacking relations excuse the overlap.
    let v = check(&r, &objs[..2], &[(Relation::In, 1, 0)]);
    assert!(v.overlaps.is_empty());
    // A box walled into a corner by two others cannot be walked to.
    let objs = vec![
        obj("boxed", [0.3, 0.0, 0.3], [0.6, 1.0, 0.6]),
        obj("w1", [1.0, 0.0, 1.3], [2.0, 1.0, 0.4]),
        obj("w2", [1.6, 0.0, 0.5], [0.4, 1.0, 1.0]),
    ];
    let v = check(&r, &objs, &[]);
    assert_eq!(v.unreachable, vec![0], "{v:?}");
}

fn random_item(kind: u8, k: usize) -> LayoutItem {
    let mut it = match kind % 7 {
        0 => desk(),
        1 => chair(),
        2 => lamp(),
        3 => painting(),
        4 => sofa(),
        5 => table(),
        _ => item("plant", [0.4, 1.0, 0.4], Support::Floor, false),
    };
    it.label = format!("{} {k}", it.label);
    it
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, rng_seed: proptest::test_runner::RngSeed::Fixed(inbetween_core::seed::PROPTEST_SEED), ..ProptestConfig::default() })]
    #[test]
    fn ten_random_objects_never_overlap(kinds in proptest::collection::vec(0u8..7, 10), seed in 0u64..1000, rel_seed in 0u64..1000) {
        let items: Vec<LayoutItem> = kinds.iter().enumerate().map(|(k, &t)| random_item(t, k)).collect();
        // A few random relations from later items to earlier ones.
        let rels: Vec<(Relation, usize, usize)> = (0..3)
            .map(|k| {
                let h = inbetween_core::seed::derive(rel_seed, k);
                let active = 1 + (h % 9) as usize;
                let anchor = (h >> 8) as usize % active;
                (Relation::ALL[(h >> 16) as usize % 8], active, anchor)
            })
            .collect();
        let p = LayoutProblem { room: room(6.0, 5.0), items, relations: rels.iter().map(|&(relation, active, anchor)| LayoutConstraint { relation, active, anchor }).collect(), places: vec![] };
        let out = solve(&p, seed);
        prop_assert!(out.violations.overlaps.is_empty(), "{:?}", out.violations);
        prop_assert!(out.violations.outside.is_empty());
        prop_assert!(out.violations.unreachable.is_empty());
        prop_assert_eq!(out.objects.len() + out.dropped.len(), 10);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 32, rng_seed: proptest::test_runner::RngSeed::Fixed(inbetween_core::seed::PROPTEST_SEED), ..ProptestConfig::default() })]
    /// Odd rooms and sizes (tiny, huge, zero, NaN) never panic and account for every item.
    #[test]
    fn odd_inputs_never_panic(
        w in prop_oneof![Just(0.0f32), Just(f32::NAN), 0.3f32..12.0],
        d in 0.3f32..12.0,
        sizes in proptest::collection::vec((prop_oneof![Just(0.0f32), Just(f32::INFINITY), 0.05f32..4.0], 0.05f32..3.0, 0.05f32..4.0, 0u8..4), 0..8),
        seed in 0u64..100,
    ) {
        let supports = [Support::Floor, Support::Surface, Support::Wall, Support::Ceiling];
        let items: Vec<LayoutItem> = sizes.iter().enumerate().map(|(k, &(x, y, z, s))| item(&format!("thing {k}"), [x, y, z], supports[s as usize], k % 2 == 0)).collect();
        let n = items.len();
        let rels: Vec<LayoutConstraint> = (1..n).map(|k| LayoutConstraint { relation: Relation::ALL[k % 8], active: k, anchor: k - 1 }).collect();
        let p = LayoutProblem { room: Room { name: "r".into(), width: w, depth: d, height: 2.5 }, items, relations: rels, places: vec![] };
        let out = solve(&p, seed);
        prop_assert_eq!(out.objects.len() + out.dropped.len(), n);
        prop_assert!(out.violations.overlaps.is_empty());
    }
}
