//! SSG matching: Algorithm 1 (relation-first) against the LDS object-first baseline (§4.1, Fig. 8).

use inbetween_script::catalogue::builtin::builtin;
use inbetween_script::database::SceneDatabase;
use inbetween_script::matching::{fig8, object_first, query_pool, relation_first, score};
use inbetween_script::ssg::{ObjectNode, Relation, RelationNode, Ssg};

fn obj(c: &str) -> ObjectNode {
    ObjectNode { category: c.into(), attributes: vec![], count: 1, word: c.into(), sentence: 0 }
}

fn ssg(objects: &[&str], rels: &[(usize, Relation, usize)]) -> Ssg {
    Ssg {
        objects: objects.iter().map(|c| obj(c)).collect(),
        relations: rels
            .iter()
            .map(|&(active, relation, anchor)| RelationNode { relation, active, anchor, sentence: 0 })
            .collect(),
        ..Ssg::default()
    }
}

fn mean(v: &[f64]) -> f64 {
    v.iter().sum::<f64>() / v.len() as f64
}

#[test]
fn relation_first_beats_object_first_on_the_fig8_sets() {
    let cat = builtin();
    let db = SceneDatabase::builtin(&cat, 5, 7);
    let pool = query_pool(&db, &cat, 7);
    assert_eq!(pool.len(), 20);
    let sets = fig8(&db, &cat, &pool, &[5, 10, 15], 7);
    for s in &sets {
        assert_eq!(s.relation_first.len(), s.n);
        assert!(s.relation_first.iter().chain(&s.object_first).all(|x| (0.0..=1.0).contains(x)));
        let (r, o) = (mean(&s.relation_first), mean(&s.object_first));
        println!("n = {:2}: relation-first {r:.3}, object-first {o:.3}", s.n);
        assert!(r >= o, "n = {}: {r} < {o}", s.n);
    }
    // Over the whole pool, relation-first is never worse on a query and better on most.
    let all = fig8(&db, &cat, &pool, &[20], 1).remove(0);
    let better = all.relation_first.iter().zip(&all.object_first).filter(|(r, o)| r > o).count();
    for (i, (r, o)) in all.relation_first.iter().zip(&all.object_first).enumerate() {
        assert!(r + 1e-9 >= *o, "query {}: {r} < {o}", all.queries[i]);
    }
    assert!(better >= 8, "only {better} of 20 queries improve");
}

#[test]
fn a_relation_found_in_one_scene_gets_that_scene() {
    let cat = builtin();
    let db = SceneDatabase::builtin(&cat, 0, 0);
    // Only the meeting room hangs a clock above a blackboard; only the workshop puts wood on a table.
    for (q, room) in [
        (ssg(&["clock", "blackboard"], &[(0, Relation::Above, 1)]), "meetingroom"),
        (ssg(&["table", "wood", "hammer"], &[(1, Relation::On, 0), (2, Relation::On, 0)]), "workshop"),
        (ssg(&["desk", "recorder"], &[(1, Relation::On, 0)]), "musicroom"),
    ] {
        let m = relation_first(&q, &db, &cat);
        assert!(m.unmatched.is_empty());
        for e in &m.entries {
            assert_eq!(db.scenes[e.scene].name, room, "{q:?}");
            assert!(e.via_relation);
        }
        assert_eq!(score(&q, &db, &m), 1.0);
    }
}

#[test]
fn classmates_match_when_the_category_is_missing() {
    let cat = builtin();
    let db = SceneDatabase::builtin(&cat, 0, 0);
    // Fig. 4: a desklamp on a table. The database has it on a desk (class "table").
    let q = ssg(&["table", "desklamp"], &[(1, Relation::On, 0)]);
    let m = relation_first(&q, &db, &cat);
    let e = m.get(0).unwrap();
    assert_eq!(db.scenes[e.scene].ssg.objects[e.db_node].category, "desk");
    assert!((score(&q, &db, &m) - (0.5 + 1.0 + 1.0) / 3.0).abs() < 1e-9);
}

#[test]
fn falls_back_to_objects_when_no_relation_matches() {
    let cat = builtin();
    let db = SceneDatabase::builtin(&cat, 2, 0);
    let q = ssg(&["bed", "piano", "unicorn"], &[(0, Relation::On, 1)]);
    let m = relation_first(&q, &db, &cat);
    assert_eq!(m.unmatched, vec![2]);
    assert_eq!(m.entries.len(), 2);
    assert!(m.entries.iter().all(|e| !e.via_relation));
    assert_eq!(db.scenes[m.get(0).unwrap().scene].ssg.objects[m.get(0).unwrap().db_node].category, "bed");
    assert!((score(&q, &db, &m) - 2.0 / 4.0).abs() < 1e-9);
    // An empty query matches nothing and scores 1.
    let empty = Ssg::default();
    assert_eq!(relation_first(&empty, &db, &cat), Default::default());
    assert_eq!(score(&empty, &db, &object_first(&empty, &db, &cat)), 1.0);
}

#[test]
fn matching_is_deterministic() {
    let cat = builtin();
    let db = SceneDatabase::builtin(&cat, 3, 5);
    let pool = query_pool(&db, &cat, 5);
    assert_eq!(pool, query_pool(&db, &cat, 5));
    assert_eq!(fig8(&db, &cat, &pool, &[5, 10, 15], 3), fig8(&db, &cat, &pool, &[5, 10, 15], 3));
    for q in &pool {
        assert_eq!(relation_first(q, &db, &cat), relation_first(q, &db, &cat));
        assert_eq!(object_first(q, &db, &cat), object_first(q, &db, &cat));
    }
}

#[test]
fn matching_is_fast_enough_for_incremental_edits() {
    let cat = builtin();
    let db = SceneDatabase::builtin(&cat, 5, 1);
    let pool = query_pool(&db, &cat, 1);
    let mut big = Ssg::default();
    for q in pool.iter().take(4) {
        big.merge(q.clone());
    }
    let t = std::time::Instant::now();
    let m = relation_first(&big, &db, &cat);
    let ms = t.elapsed().as_secs_f64() * 1e3;
    println!("{} objects, {} relations: {ms:.1} ms", big.objects.len(), big.relations.len());
    assert_eq!(m.entries.len() + m.unmatched.len(), big.objects.len());
    assert!(ms < 500.0, "{ms} ms");
}
