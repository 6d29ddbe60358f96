//! Every built-in database scene re-laid out from its own placements as hints: no violations,
//! nothing dropped, and most objects keep their authored pose.

use inbetween_script::catalogue::builtin::builtin;
use inbetween_script::database::SceneDatabase;
use inbetween_script::layout::{solve, LayoutConstraint, LayoutItem, LayoutProblem};
use inbetween_script::scene::Origin;

#[test]
fn database_scenes_lay_out_cleanly_from_their_hints() {
    let cat = builtin();
    let db = SceneDatabase::builtin(&cat, 2, 7);
    assert!(!db.scenes.is_empty());
    let (mut kept, mut total) = (0, 0);
    for s in &db.scenes {
        let items: Vec<LayoutItem> = s
            .ssg
            .objects
            .iter()
            .zip(&s.placements)
            .enumerate()
            .map(|(k, (o, p))| {
                let c = cat.get(&o.category).unwrap_or_else(|| panic!("{}: unknown category {}", s.name, o.category));
                LayoutItem {
                    label: format!("{} {k}", o.category),
                    category: o.category.clone(),
                    attributes: o.attributes.clone(),
                    size: p.size,
                    support: c.support,
                    surface: c.surface,
                    origin: Origin::Database { scene: s.name.clone(), node: k },
                    hint: Some(p.clone()),
                    pinned: None,
                    seat: c.is_seat(),
                }
            })
            .collect();
        let relations = s
            .ssg
            .relations
            .iter()
            .map(|r| LayoutConstraint { relation: r.relation, active: r.active, anchor: r.anchor })
            .collect();
        let p = LayoutProblem { room: s.room.clone(), items, relations, places: vec![] };
        let t = std::time::Instant::now();
        let out = solve(&p, 1);
        let ms = t.elapsed().as_secs_f64() * 1e3;
        assert!(out.dropped.is_empty(), "{}: dropped {:?}", s.name, out.dropped);
        assert_eq!(out.violations.total(), 0, "{}: {:?}", s.name, out.violations);
        for (k, it) in p.items.iter().enumerate() {
            total += 1;
            let o = &out.objects[out.placed[k].unwrap()];
            if o.position == it.hint.as_ref().unwrap().position {
                kept += 1;
            }
        }
        eprintln!("{}: {} objects in {ms:.1} ms", s.name, p.items.len());
    }
    eprintln!("kept {kept}/{total} authored poses");
    assert!(kept * 10 >= total * 7, "kept only {kept}/{total} authored poses");
}
