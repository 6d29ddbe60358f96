//! The hand-authored database rooms: one per scene of the paper's figures (Fig. 1, 5–7: office,
//! bedroom, living room, gallery, music room, meeting room, workshop, boxing gym). Coordinates are
//! room metres (x across, z into the room from the back wall at z = 0, which wall objects face
//! away from); each scene lists the relations its author meant, which the tests check hold.

use std::f32::consts::{FRAC_PI_2 as QUARTER, PI};

use super::Item;
use crate::catalogue::Catalogue;
use crate::scene::Room;
use crate::ssg::Relation::{self, *};

/// An authored room before it becomes a [`super::DbScene`].
pub(crate) struct Authored {
    pub name: &'static str,
    pub room: Room,
    pub items: Vec<Item>,
    /// (active, relation, anchor) the author meant.
    pub intended: Vec<(usize, Relation, usize)>,
}

struct B<'a> {
    cat: &'a Catalogue,
    a: Authored,
}

impl<'a> B<'a> {
    fn new(cat: &'a Catalogue, name: &'static str) -> B<'a> {
        let kind = cat.resolve_room(name).unwrap_or_else(|| panic!("room kind {name}"));
        let room = Room { name: kind.name.clone(), width: kind.size[0], depth: kind.size[2], height: kind.size[1] };
        B { cat, a: Authored { name, room, items: Vec::new(), intended: Vec::new() } }
    }

    fn push(&mut self, c: &str, attrs: &[&str], pos: [f32; 3], yaw: f32, parent: Option<usize>) -> usize {
        let size = self.cat.get(c).unwrap_or_else(|| panic!("category {c}")).size;
        self.a.items.push(Item {
            category: c.to_string(),
            attributes: attrs.iter().map(|s| s.to_string()).collect(),
            position: pos,
            yaw,
            size,
            parent,
        });
        self.a.items.len() - 1
    }

    /// On the floor.
    fn floor(&mut self, c: &str, attrs: &[&str], x: f32, z: f32, yaw: f32) -> usize {
        self.push(c, attrs, [x, 0.0, z], yaw, None)
    }

    /// Resting on `parent`'s top.
    fn on(&mut self, c: &str, attrs: &[&str], parent: usize, x: f32, z: f32, yaw: f32) -> usize {
        let y = self.a.items[parent].position[1] + self.a.items[parent].size[1];
        let i = self.push(c, attrs, [x, y, z], yaw, Some(parent));
        self.rel(i, On, parent)
    }

    /// Inside `parent` at base height `y`.
    fn inside(&mut self, c: &str, attrs: &[&str], parent: usize, x: f32, y: f32, z: f32) -> usize {
        let i = self.push(c, attrs, [x, y, z], 0.0, Some(parent));
        self.rel(i, In, parent)
    }

    /// On a wall or hanging: free base height `y`.
    fn hung(&mut self, c: &str, attrs: &[&str], x: f32, y: f32, z: f32, yaw: f32) -> usize {
        self.push(c, attrs, [x, y, z], yaw, None)
    }

    fn resize(&mut self, i: usize, size: [f32; 3]) {
        self.a.items[i].size = size;
    }

    fn rel(&mut self, a: usize, r: Relation, b: usize) -> usize {
        self.a.intended.push((a, r, b));
        a
    }
}

/// All authored rooms.
pub(crate) fn authored(cat: &Catalogue) -> Vec<Authored> {
    vec![
        office(cat),
        bedroom(cat),
        livingroom(cat),
        gallery(cat),
        musicroom(cat),
        meetingroom(cat),
        workshop(cat),
        boxinggym(cat),
    ]
}

/// "In the room, an organized office desk is near a bed" (Fig. 1) and Fig. 4's desk scene.
fn office(cat: &Catalogue) -> Authored {
    let mut b = B::new(cat, "office");
    let desk = b.floor("desk", &["office", "organized", "wooden"], 2.5, 0.36, 0.0);
    let chair = b.floor("officechair", &["black", "modern"], 2.5, 1.11, PI);
    b.rel(chair, InFrontOf, desk);
    b.on("computer", &["black"], desk, 2.5, 0.25, 0.0);
    b.on("desklamp", &[], desk, 1.95, 0.25, 0.0);
    b.on("keyboard", &[], desk, 2.5, 0.55, 0.0);
    b.on("cup", &["white"], desk, 3.0, 0.5, 0.0);
    let shelf = b.floor("bookshelf", &["wooden"], 0.6, 0.2, 0.0);
    b.inside("book", &[], shelf, 0.6, 0.9, 0.2);
    b.floor("plant", &["green"], 4.6, 0.3, 0.0);
    let bin = b.floor("trashcan", &[], 3.5, 0.3, 0.0);
    b.rel(bin, NextTo, desk);
    let pic = b.hung("picture", &["framed"], 2.5, 1.4, 0.02, 0.0);
    b.rel(pic, Above, desk);
    let arm = b.floor("armchair", &["leather"], 0.7, 3.6, QUARTER);
    let table = b.floor("coffeetable", &[], 1.8, 3.6, QUARTER);
    b.rel(table, InFrontOf, arm);
    b.on("phone", &[], table, 1.8, 3.6, 0.0);
    let rug = b.floor("rug", &["red"], 1.5, 3.6, 0.0);
    b.rel(rug, Under, table);
    b.a
}

fn bedroom(cat: &Catalogue) -> Authored {
    let mut b = B::new(cat, "bedroom");
    let bed = b.floor("bed", &["double", "comfortable"], 2.25, 1.08, 0.0);
    let ns1 = b.floor("nightstand", &["wooden"], 1.0, 0.25, 0.0);
    b.rel(ns1, NextTo, bed);
    b.on("lamp", &["warm"], ns1, 1.0, 0.25, 0.0);
    let ns2 = b.floor("nightstand", &["wooden"], 3.5, 0.25, 0.0);
    b.rel(ns2, NextTo, bed);
    b.on("book", &[], ns2, 3.5, 0.25, 0.0);
    b.floor("wardrobe", &["large"], 3.85, 3.65, PI);
    let desk = b.floor("desk", &["small"], 0.4, 2.9, QUARTER);
    let chair = b.floor("chair", &["wooden"], 1.1, 2.9, -QUARTER);
    b.rel(chair, InFrontOf, desk);
    b.on("laptop", &[], desk, 0.4, 2.9, QUARTER);
    let rug = b.floor("rug", &["soft"], 2.25, 2.9, 0.0);
    b.rel(rug, InFrontOf, bed);
    let pic = b.hung("picture", &[], 2.25, 1.0, 0.02, 0.0);
    b.rel(pic, Above, bed);
    b.on("pillow", &[], bed, 2.25, 0.4, 0.0);
    b.floor("plant", &[], 4.2, 2.0, 0.0);
    b.a
}

fn livingroom(cat: &Catalogue) -> Authored {
    let mut b = B::new(cat, "livingroom");
    let sofa = b.floor("sofa", &["comfortable", "grey"], 3.0, 0.47, 0.0);
    let table = b.floor("coffeetable", &["wooden"], 3.0, 1.8, 0.0);
    b.rel(table, InFrontOf, sofa);
    let rug = b.floor("rug", &["round"], 3.0, 1.8, 0.0);
    b.rel(rug, Under, table);
    let cab = b.floor("cabinet", &[], 3.0, 4.75, PI);
    b.on("tv", &["vintage"], cab, 3.0, 4.75, PI);
    let arm = b.floor("armchair", &[], 1.2, 1.8, QUARTER);
    b.rel(arm, Near, table);
    let lamp = b.floor("floorlamp", &[], 1.0, 0.5, 0.0);
    b.rel(lamp, Near, sofa);
    b.on("teapot", &[], table, 2.8, 1.8, 0.0);
    b.on("cup", &[], table, 3.2, 1.8, 0.0);
    let art = b.hung("oilpainting", &["large"], 3.0, 1.3, 0.025, 0.0);
    b.rel(art, Above, sofa);
    b.floor("plant", &["tall"], 5.6, 0.4, 0.0);
    b.floor("bookshelf", &[], 5.8, 2.5, -QUARTER);
    let side = b.floor("nightstand", &["side"], 4.35, 0.4, 0.0);
    b.rel(side, NextTo, sofa);
    b.on("vase", &["blue"], side, 4.35, 0.4, 0.0);
    b.a
}

/// "In a gallery there is a horsesculpture and a oilpainting. There is also a sculpture and a picture" (Fig. 5).
fn gallery(cat: &Catalogue) -> Authored {
    let mut b = B::new(cat, "gallery");
    let p1 = b.hung("oilpainting", &["famous"], 2.0, 1.3, 0.025, 0.0);
    let p2 = b.hung("oilpainting", &[], 6.0, 1.3, 0.025, 0.0);
    b.hung("picture", &[], 0.02, 1.4, 3.0, QUARTER);
    b.hung("picture", &[], 7.98, 1.4, 3.0, -QUARTER);
    let horse = b.floor("horsesculpture", &["bronze"], 4.0, 3.0, PI);
    let sculpture = b.floor("sculpture", &["marble"], 4.0, 4.5, 0.0);
    b.rel(sculpture, Behind, horse);
    let b1 = b.floor("bench", &[], 2.0, 1.5, PI);
    b.rel(b1, InFrontOf, p1);
    let b2 = b.floor("bench", &[], 6.0, 1.5, PI);
    b.rel(b2, InFrontOf, p2);
    b.floor("plant", &[], 7.6, 5.6, 0.0);
    b.floor("trashcan", &[], 0.4, 5.6, 0.0);
    b.floor("floorlamp", &[], 7.6, 0.4, 0.0);
    b.floor("sculpture", &["small"], 2.0, 4.5, 0.0);
    b.a
}

/// "A computer and a recorder are on a desk. There is a piano and a chair in front" (Fig. 5).
fn musicroom(cat: &Catalogue) -> Authored {
    let mut b = B::new(cat, "musicroom");
    let desk = b.floor("desk", &[], 1.5, 0.36, 0.0);
    b.on("computer", &[], desk, 1.3, 0.25, 0.0);
    b.on("recorder", &["sound"], desk, 1.85, 0.3, 0.0);
    b.on("microphone", &[], desk, 2.1, 0.55, 0.0);
    b.on("headphones", &[], desk, 0.95, 0.55, 0.0);
    let chair = b.floor("chair", &["modern"], 1.5, 1.1, PI);
    b.rel(chair, InFrontOf, desk);
    let piano = b.floor("piano", &["black"], 3.9, 0.32, 0.0);
    let stool = b.floor("stool", &[], 3.9, 0.95, PI);
    b.rel(stool, InFrontOf, piano);
    b.floor("guitar", &[], 4.7, 2.0, -QUARTER);
    let speaker = b.floor("speaker", &[], 2.75, 0.3, 0.0);
    b.rel(speaker, NextTo, piano);
    b.floor("drum", &[], 1.0, 3.7, 0.0);
    let pic = b.hung("picture", &[], 3.9, 1.5, 0.02, 0.0);
    b.rel(pic, Above, piano);
    b.a
}

/// "There is a blackboard in a meetingroom. There is an arranged table in the meetingroom" (Fig. 7).
fn meetingroom(cat: &Catalogue) -> Authored {
    let mut b = B::new(cat, "meetingroom");
    let board = b.hung("blackboard", &[], 3.0, 0.9, 0.025, 0.0);
    let table = b.floor("table", &["arranged", "meeting", "long"], 3.0, 2.7, 0.0);
    b.resize(table, [2.4, 0.75, 1.0]);
    for x in [2.4, 3.6] {
        let c = b.floor("chair", &[], x, 3.55, PI);
        b.rel(c, InFrontOf, table);
        let c = b.floor("chair", &[], x, 1.85, 0.0);
        b.rel(c, Behind, table);
    }
    b.on("laptop", &[], table, 2.4, 2.7, 0.0);
    b.on("projector", &[], table, 3.0, 2.7, 0.0);
    b.on("cup", &[], table, 3.6, 2.9, 0.0);
    b.hung("whiteboard", &[], 5.975, 0.9, 2.5, -QUARTER);
    b.floor("plant", &[], 0.4, 4.6, 0.0);
    let clock = b.hung("clock", &[], 3.0, 2.2, 0.025, 0.0);
    b.rel(clock, Above, board);
    b.a
}

/// "There is an organized working shop. A hammer and a wood is on the table. A shelf and a sofa are
/// in the front" (Fig. 5).
fn workshop(cat: &Catalogue) -> Authored {
    let mut b = B::new(cat, "workshop");
    let bench = b.floor("workbench", &["organized"], 3.0, 0.4, 0.0);
    let table = b.floor("table", &["wooden"], 3.0, 2.5, 0.0);
    b.on("hammer", &[], table, 2.75, 2.4, 0.0);
    b.on("wood", &[], table, 3.0, 2.7, 0.0);
    b.on("saw", &[], bench, 2.6, 0.4, 0.0);
    b.on("nail", &[], bench, 3.1, 0.55, 0.0);
    b.on("toolbox", &["red"], bench, 3.6, 0.3, 0.0);
    let shelf = b.floor("bookshelf", &[], 3.0, 3.9, PI);
    b.rel(shelf, InFrontOf, table);
    let sofa = b.floor("sofa", &["old"], 4.6, 4.45, PI);
    b.rel(sofa, InFrontOf, table);
    b.floor("stool", &[], 1.0, 1.0, 0.0);
    let bin = b.floor("trashcan", &[], 1.8, 0.3, 0.0);
    b.rel(bin, NextTo, bench);
    b.floor("box", &["cardboard"], 5.5, 0.3, 0.0);
    b.floor("floorlamp", &[], 5.6, 2.5, 0.0);
    b.a
}

/// "There is a boxing ring above which a boxingbag hangs. There is a stool and a desk. There is a
/// bottle" (Fig. 7).
fn boxinggym(cat: &Catalogue) -> Authored {
    let mut b = B::new(cat, "boxinggym");
    let ring = b.floor("boxingring", &[], 4.0, 3.5, 0.0);
    let bag = b.hung("boxingbag", &["red"], 4.0, 1.6, 3.5, 0.0);
    b.rel(bag, Above, ring);
    let bag2 = b.hung("boxingbag", &["heavy"], 7.2, 0.9, 1.0, 0.0);
    let stool = b.floor("stool", &[], 1.55, 3.5, 0.0);
    b.rel(stool, NextTo, ring);
    let desk = b.floor("desk", &[], 1.0, 0.36, 0.0);
    b.on("bottle", &["water"], desk, 0.8, 0.36, 0.0);
    b.on("soda", &[], desk, 1.2, 0.4, 0.0);
    b.floor("bench", &[], 6.9, 6.6, PI);
    b.floor("dumbbell", &[], 5.0, 6.5, 0.0);
    b.on("stool", &[], ring, 2.6, 2.1, 0.0);
    b.floor("trashcan", &[], 0.3, 6.6, 0.0);
    b.floor("speaker", &[], 7.7, 0.2, 0.0);
    let mat = b.floor("rug", &["mat"], 7.0, 1.0, 0.0);
    b.rel(mat, Under, bag2);
    b.a
}
