//! The built-in box-model catalogue (no files needed): every object named in the paper's figure
//! captions (Fig. 1, 5–7: desk, modernchair, oilpainting, horsesculpture, boxingbag, recorder, …)
//! plus what typical rooms hold. Sizes are typical furniture dimensions in metres (w × h × d);
//! contact points follow NSM's interaction points as the paper uses them (§5.1).

use super::{Catalogue, Category, ContactKind, ContactPoint, RoomKind, Support};
use ContactKind::{Grip, Keys, Seat, Stand, Strike, Top};
use Support::{Ceiling, Floor, Surface, Wall};

/// One catalogue row: name, synonyms, class, size, support, surface, colour, contacts.
type Row = (
    &'static str,
    &'static [&'static str],
    &'static str,
    [f32; 3],
    Support,
    bool,
    [u8; 3],
    &'static [(ContactKind, [f32; 3])],
);

/// Stand points are floor points in front of the object: only x and z count (the character stands
/// on the floor whatever the object's base height).
#[rustfmt::skip]
const ROWS: &[Row] = &[
    // Tables and other surfaces.
    ("desk", &["officedesk", "writingdesk", "computerdesk", "studydesk"], "table", [1.4, 0.75, 0.7], Floor, true, [150, 110, 70], &[(Top, [0.0, 0.75, 0.0])]),
    ("table", &["worktable", "roundtable", "kitchentable"], "table", [1.2, 0.75, 0.8], Floor, true, [160, 120, 80], &[(Top, [0.0, 0.75, 0.0])]),
    ("coffeetable", &["teatable", "lowtable", "tablecoffee"], "table", [1.0, 0.45, 0.6], Floor, true, [170, 130, 90], &[(Top, [0.0, 0.45, 0.0])]),
    ("diningtable", &["dinnertable", "conferencetable", "meetingtable"], "table", [1.8, 0.75, 0.9], Floor, true, [140, 100, 60], &[(Top, [0.0, 0.75, 0.0])]),
    ("nightstand", &["bedsidetable", "sidetable", "endtable", "nighttable"], "table", [0.5, 0.55, 0.4], Floor, true, [150, 120, 90], &[(Top, [0.0, 0.55, 0.0])]),
    ("workbench", &["carpenterbench", "worktop"], "table", [1.8, 0.9, 0.75], Floor, true, [130, 95, 60], &[(Top, [0.0, 0.9, 0.0]), (Stand, [0.0, 0.0, 0.7])]),
    // Seats.
    ("chair", &["modernchair", "seat", "diningchair", "woodenchair"], "seat", [0.5, 0.9, 0.5], Floor, false, [90, 120, 160], &[(Seat, [0.0, 0.45, 0.0])]),
    ("officechair", &["deskchair", "swivelchair", "chairdesk"], "seat", [0.6, 1.0, 0.6], Floor, false, [60, 70, 90], &[(Seat, [0.0, 0.48, 0.0])]),
    ("stool", &["barstool", "footstool"], "seat", [0.4, 0.65, 0.4], Floor, false, [120, 100, 80], &[(Seat, [0.0, 0.65, 0.0])]),
    ("armchair", &["easychair", "recliner", "lounger"], "seat", [0.85, 0.95, 0.85], Floor, false, [130, 90, 110], &[(Seat, [0.0, 0.42, 0.05])]),
    ("bench", &["parkbench", "gymbench"], "seat", [1.4, 0.45, 0.4], Floor, false, [110, 90, 70], &[(Seat, [0.0, 0.45, 0.0]), (Seat, [-0.45, 0.45, 0.0]), (Seat, [0.45, 0.45, 0.0])]),
    ("sofa", &["couch", "settee", "loungesofa", "loveseat"], "seat", [2.0, 0.85, 0.9], Floor, false, [120, 80, 130], &[(Seat, [0.0, 0.45, 0.05]), (Seat, [-0.55, 0.45, 0.05]), (Seat, [0.55, 0.45, 0.05])]),
    ("bed", &["singlebed", "doublebed", "bedsingle"], "bed", [1.6, 0.55, 2.1], Floor, false, [200, 200, 220], &[(Seat, [0.0, 0.55, 0.7])]),
    // Storage.
    ("wardrobe", &["closet", "armoire"], "storage", [1.2, 2.0, 0.6], Floor, false, [120, 90, 60], &[(Stand, [0.0, 0.0, 0.7]), (Grip, [0.1, 1.0, 0.3])]),
    ("bookshelf", &["bookcase", "shelf", "bookshelves", "shelves", "bookcaseopen"], "storage", [0.9, 1.8, 0.35], Floor, false, [140, 110, 80], &[(Stand, [0.0, 0.0, 0.6])]),
    ("cabinet", &["dresser", "drawer", "cupboard", "tvstand", "tvcabinet", "sideboard"], "storage", [0.9, 0.8, 0.45], Floor, true, [150, 130, 100], &[(Top, [0.0, 0.8, 0.0])]),
    // Lights.
    ("lamp", &["tablelamp", "light", "lampround"], "lamp", [0.25, 0.45, 0.25], Surface, false, [240, 220, 120], &[(Grip, [0.0, 0.3, 0.0])]),
    ("desklamp", &["readinglamp", "worklamp"], "lamp", [0.2, 0.45, 0.3], Surface, false, [250, 230, 100], &[(Grip, [0.0, 0.3, 0.0])]),
    ("floorlamp", &["standinglamp", "standardlamp"], "lamp", [0.4, 1.6, 0.4], Floor, false, [240, 210, 110], &[]),
    // Art and boards.
    ("oilpainting", &["painting", "artwork", "canvas"], "art", [0.9, 0.7, 0.05], Wall, false, [200, 150, 90], &[(Stand, [0.0, 0.0, 1.0])]),
    ("picture", &["photo", "photograph", "poster", "frame", "portrait"], "art", [0.6, 0.5, 0.04], Wall, false, [210, 170, 120], &[(Stand, [0.0, 0.0, 0.9])]),
    ("horsesculpture", &["horsestatue", "horse"], "sculpture", [0.8, 1.2, 0.4], Floor, false, [180, 170, 160], &[(Stand, [0.0, 0.0, 1.0])]),
    ("sculpture", &["statue", "bust", "figurine"], "sculpture", [0.5, 1.5, 0.5], Floor, false, [190, 190, 180], &[(Stand, [0.0, 0.0, 0.9])]),
    ("blackboard", &["chalkboard"], "board", [2.0, 1.0, 0.05], Wall, false, [40, 60, 45], &[(Stand, [0.0, 0.0, 0.6]), (Grip, [0.0, 0.5, 0.03])]),
    ("whiteboard", &["board", "markerboard"], "board", [1.8, 1.0, 0.05], Wall, false, [235, 235, 235], &[(Stand, [0.0, 0.0, 0.6]), (Grip, [0.0, 0.5, 0.03])]),
    ("clock", &["wallclock"], "decor", [0.3, 0.3, 0.05], Wall, false, [220, 220, 200], &[]),
    ("mirror", &["wallmirror"], "decor", [0.6, 0.9, 0.04], Wall, false, [200, 220, 230], &[(Stand, [0.0, 0.0, 0.7])]),
    ("window", &["windowpane"], "opening", [1.2, 1.2, 0.05], Wall, false, [170, 210, 240], &[(Stand, [0.0, 0.0, 0.6])]),
    ("door", &["doorway", "entrance"], "opening", [0.9, 2.0, 0.05], Wall, false, [130, 100, 70], &[(Stand, [0.0, 0.0, 0.6]), (Grip, [0.35, 1.0, 0.05])]),
    // Boxing.
    ("boxingring", &["ring", "boxring"], "boxing", [4.0, 0.6, 4.0], Floor, true, [200, 60, 60], &[(Top, [0.0, 0.6, 0.0])]),
    ("boxingbag", &["punchingbag", "punchbag", "sandbag", "heavybag"], "boxing", [0.4, 1.1, 0.4], Ceiling, false, [150, 40, 40], &[(Strike, [0.0, 0.6, 0.2]), (Stand, [0.0, 0.0, 0.7])]),
    ("dumbbell", &["weight", "weights", "barbell"], "boxing", [0.35, 0.12, 0.12], Floor, false, [60, 60, 60], &[(Grip, [0.0, 0.06, 0.0])]),
    // Drinks and tableware.
    ("bottle", &["waterbottle", "flask"], "drink", [0.08, 0.3, 0.08], Surface, false, [80, 160, 200], &[(Grip, [0.0, 0.2, 0.0])]),
    ("soda", &["can", "coke", "drink", "sodacan", "pop"], "drink", [0.07, 0.12, 0.07], Surface, false, [220, 40, 40], &[(Grip, [0.0, 0.08, 0.0])]),
    ("cup", &["mug", "glass", "teacup", "coffeecup"], "drink", [0.09, 0.1, 0.09], Surface, false, [240, 240, 240], &[(Grip, [0.05, 0.06, 0.0])]),
    ("teapot", &["kettle", "coffeepot", "pot"], "drink", [0.22, 0.16, 0.15], Surface, false, [230, 230, 210], &[(Grip, [0.11, 0.1, 0.0])]),
    ("vase", &["flowervase", "jar", "urn"], "decor", [0.15, 0.3, 0.15], Surface, false, [100, 140, 200], &[(Grip, [0.0, 0.2, 0.0])]),
    ("book", &["books", "notebook", "novel", "magazine"], "book", [0.16, 0.04, 0.23], Surface, false, [180, 60, 60], &[(Grip, [0.0, 0.02, 0.0])]),
    ("pillow", &["cushion", "pillowblue"], "decor", [0.5, 0.12, 0.35], Surface, false, [120, 150, 210], &[]),
    // Tools and materials.
    ("hammer", &["mallet"], "tool", [0.3, 0.04, 0.12], Surface, false, [110, 80, 50], &[(Grip, [-0.1, 0.02, 0.0])]),
    ("saw", &["handsaw"], "tool", [0.6, 0.03, 0.15], Surface, false, [170, 170, 180], &[(Grip, [-0.25, 0.02, 0.0])]),
    ("nail", &["nails", "screw", "screws"], "tool", [0.02, 0.08, 0.02], Surface, false, [150, 150, 150], &[(Grip, [0.0, 0.06, 0.0])]),
    ("toolbox", &["toolkit", "toolcase"], "tool", [0.5, 0.25, 0.25], Surface, false, [200, 60, 40], &[(Grip, [0.0, 0.25, 0.0])]),
    ("wood", &["plank", "lumber", "timber", "log", "woodboard"], "material", [1.2, 0.05, 0.2], Surface, false, [190, 150, 100], &[(Grip, [-0.4, 0.05, 0.0]), (Top, [0.0, 0.05, 0.0])]),
    ("box", &["cardboardbox", "crate", "carton", "package"], "material", [0.4, 0.3, 0.3], Floor, true, [190, 160, 110], &[(Grip, [0.0, 0.15, 0.15])]),
    // Computers and screens.
    ("computer", &["pc", "desktop", "workstation", "imac"], "computer", [0.5, 0.45, 0.25], Surface, false, [70, 70, 80], &[(Keys, [0.0, 0.02, 0.3])]),
    ("laptop", &["macbook", "notebookcomputer"], "computer", [0.35, 0.03, 0.25], Surface, false, [150, 150, 160], &[(Keys, [0.0, 0.03, 0.05])]),
    ("keyboard", &["typewriter", "computerkeyboard"], "computer", [0.45, 0.03, 0.15], Surface, false, [50, 50, 50], &[(Keys, [0.0, 0.03, 0.0])]),
    ("monitor", &["screen", "display"], "screen", [0.55, 0.4, 0.2], Surface, false, [30, 30, 40], &[]),
    ("tv", &["television", "televisionvintage", "telly"], "screen", [1.0, 0.6, 0.15], Surface, false, [20, 20, 30], &[(Stand, [0.0, 0.0, 1.5])]),
    ("projector", &["beamer"], "screen", [0.3, 0.1, 0.25], Surface, false, [90, 90, 100], &[]),
    ("phone", &["cellphone", "smartphone", "mobile", "telephone", "mobilephone"], "phone", [0.08, 0.01, 0.16], Surface, false, [30, 30, 30], &[(Grip, [0.0, 0.01, 0.0])]),
    // Audio and instruments.
    ("recorder", &["soundrecorder", "taperecorder", "cassetteplayer", "recordplayer"], "audio", [0.3, 0.12, 0.2], Surface, false, [90, 90, 110], &[(Stand, [0.0, 0.0, 0.5]), (Grip, [0.0, 0.12, 0.05])]),
    ("microphone", &["mic", "micro"], "audio", [0.06, 0.2, 0.06], Surface, false, [40, 40, 40], &[(Grip, [0.0, 0.12, 0.0])]),
    ("headphones", &["headphone", "headset", "earphones", "earphone"], "audio", [0.2, 0.2, 0.1], Surface, false, [30, 30, 30], &[(Grip, [0.0, 0.2, 0.0])]),
    ("speaker", &["loudspeaker", "amplifier", "amp"], "audio", [0.3, 0.5, 0.3], Floor, false, [50, 50, 50], &[]),
    ("piano", &["uprightpiano", "grandpiano"], "instrument", [1.5, 1.2, 0.6], Floor, false, [30, 25, 25], &[(Keys, [0.0, 0.72, 0.3]), (Stand, [0.0, 0.0, 0.7])]),
    ("guitar", &["acousticguitar", "electricguitar"], "instrument", [0.4, 1.0, 0.12], Floor, false, [190, 120, 60], &[(Grip, [0.0, 0.7, 0.0])]),
    ("drum", &["drums", "drumkit", "drumset"], "instrument", [1.2, 1.0, 1.0], Floor, false, [180, 40, 60], &[(Strike, [0.0, 0.6, 0.2])]),
    // Room fittings.
    ("plant", &["pottedplant", "flower", "flowers", "houseplant", "flowerpot"], "plant", [0.4, 0.9, 0.4], Floor, false, [60, 150, 70], &[]),
    ("rug", &["carpet", "mat", "doormat", "ruground"], "rug", [2.0, 0.01, 1.4], Floor, false, [170, 90, 80], &[]),
    ("trashcan", &["trash", "bin", "dustbin", "wastebasket", "garbagecan", "wastebin"], "bin", [0.35, 0.5, 0.35], Floor, false, [110, 110, 110], &[]),
    ("fridge", &["refrigerator", "freezer", "kitchenfridge"], "kitchen", [0.7, 1.8, 0.7], Floor, false, [225, 225, 230], &[(Stand, [0.0, 0.0, 0.7]), (Grip, [0.3, 1.1, 0.35])]),
    ("sink", &["washbasin", "basin", "kitchensink"], "kitchen", [0.6, 0.9, 0.55], Floor, false, [200, 210, 220], &[(Stand, [0.0, 0.0, 0.55]), (Top, [0.0, 0.9, 0.0])]),
    ("stove", &["oven", "cooker", "hob"], "kitchen", [0.6, 0.9, 0.6], Floor, false, [80, 80, 90], &[(Stand, [0.0, 0.0, 0.6]), (Top, [0.0, 0.9, 0.0])]),
    ("counter", &["kitchencabinet", "countertop", "kitchencounter"], "kitchen", [1.2, 0.9, 0.6], Floor, true, [200, 190, 170], &[(Top, [0.0, 0.9, 0.0]), (Stand, [0.0, 0.0, 0.6])]),
    // Outdoors ("Eve walks to the house", "The man walks to the road").
    ("house", &["building", "home", "cottage"], "building", [8.0, 6.0, 8.0], Floor, false, [200, 180, 150], &[(Stand, [0.0, 0.0, 4.6])]),
    ("road", &["path", "lane", "sidewalk", "pavement"], "ground", [4.0, 0.02, 20.0], Floor, false, [90, 90, 95], &[]),
    ("tree", &["oak", "pine"], "plant", [1.5, 5.0, 1.5], Floor, false, [50, 120, 50], &[]),
    ("car", &["automobile", "vehicle"], "vehicle", [1.8, 1.5, 4.5], Floor, true, [60, 80, 160], &[(Grip, [0.9, 1.0, 0.5])]),
];

/// Lowest table a seated person puts their legs under, metres.
const KNEE_HEIGHT: f32 = 0.6;

/// Whether a category is a table with room for legs below its top (class "table", at least knee
/// high: desk, table, dining table, workbench), so its collision model is a top slab on four legs
/// rather than a solid block (see `optimize::boxes`).
pub fn has_leg_room(category: &str) -> bool {
    ROWS.iter().any(|r| r.0 == category && r.2 == "table" && r.3[1] >= KNEE_HEIGHT)
}

/// Whether a seat of category `seat` placed in front of an `anchor` is pushed in under it (a chair
/// at a desk, a stool at a workbench): upright seats with no arms, at a table with leg room.
pub fn tucks_under(seat: &str, anchor: &str) -> bool {
    tucking_seat(seat) && has_leg_room(anchor)
}

/// Seats that are tucked under a table with leg room they stand in front of.
pub fn tucking_seat(seat: &str) -> bool {
    matches!(seat, "chair" | "officechair" | "stool")
}

fn room(name: &str, synonyms: &[&str], size: [f32; 3]) -> RoomKind {
    RoomKind { name: name.to_string(), synonyms: synonyms.iter().map(|s| s.to_string()).collect(), size }
}

/// The built-in catalogue: 70 categories in classes (classmates match partially, §4.1) and the
/// room kinds of the paper's scenes.
pub fn builtin() -> Catalogue {
    let categories = ROWS
        .iter()
        .map(|&(name, synonyms, _, size, support, surface, color, contacts)| Category {
            name: name.to_string(),
            synonyms: synonyms.iter().map(|s| s.to_string()).collect(),
            size,
            support,
            surface,
            contacts: contacts.iter().map(|&(kind, local)| ContactPoint { kind, local }).collect(),
            color,
            model: None,
        })
        .collect();
    let rooms = vec![
        room("room", &["place", "space", "scene", "interior"], [5.0, 2.8, 4.5]),
        room("office", &["study", "workplace", "officeroom"], [5.0, 2.8, 4.5]),
        room("bedroom", &["bed room", "dormitory", "dorm"], [4.5, 2.7, 4.0]),
        room(
            "livingroom",
            &["living room", "lounge", "sittingroom", "sitting room", "parlour", "parlor"],
            [6.0, 2.8, 5.0],
        ),
        room("gallery", &["artgallery", "art gallery", "museum", "exhibition", "exhibitionhall"], [8.0, 3.5, 6.0]),
        room("musicroom", &["music room", "studio", "recordingstudio", "recording studio"], [5.0, 2.8, 4.5]),
        room(
            "meetingroom",
            &["meeting room", "conferenceroom", "conference room", "classroom", "boardroom"],
            [6.0, 2.8, 5.0],
        ),
        room("workshop", &["working shop", "workingshop", "workroom", "garage", "shop"], [6.0, 3.0, 5.0]),
        room("boxinggym", &["boxing gym", "gym", "boxingclub", "boxing club", "fitnessroom"], [8.0, 3.5, 7.0]),
        room("kitchen", &["kitchenette", "cookroom"], [4.0, 2.7, 3.5]),
        room("street", &["outdoors", "outdoor", "outside", "park", "yard", "garden", "town"], [20.0, 10.0, 24.0]),
    ];
    Catalogue::new(categories, rooms).with_classes(ROWS.iter().map(|r| (r.0, r.2)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn caption_words_resolve() {
        let c = builtin();
        for w in [
            "desk",
            "bed",
            "modernchair",
            "oilpainting",
            "horsesculpture",
            "sculpture",
            "picture",
            "blackboard",
            "table",
            "boxingring",
            "boxingbag",
            "stool",
            "bottle",
            "soda",
            "hammer",
            "wood",
            "shelf",
            "sofa",
            "couch",
            "computer",
            "recorder",
            "piano",
            "chair",
            "microphone",
            "headphones",
            "phone",
            "saw",
            "nail",
            "vase",
            "teapot",
            "house",
            "road",
            "laptop",
            "keyboard",
            "desklamp",
        ] {
            assert!(c.resolve(w).is_some(), "{w}");
        }
        assert_eq!(c.resolve("couch").unwrap().name, "sofa");
        for r in
            ["office", "gallery", "meetingroom", "working shop", "music room", "boxing gym", "living room", "street"]
        {
            assert!(c.resolve_room(r).is_some(), "{r}");
        }
    }

    #[test]
    fn desks_and_tables_have_leg_room_but_cabinets_and_low_tables_do_not() {
        for c in ["desk", "table", "diningtable", "workbench"] {
            assert!(has_leg_room(c), "{c}");
        }
        for c in ["counter", "coffeetable", "nightstand", "sofa", "chair", "no-such-thing"] {
            assert!(!has_leg_room(c), "{c}");
        }
    }

    #[test]
    fn names_are_unique_and_sane() {
        let c = builtin();
        let mut words = std::collections::HashSet::new();
        for cat in c.categories() {
            for w in std::iter::once(&cat.name).chain(&cat.synonyms) {
                assert!(words.insert(w.clone()), "word {w} used twice");
            }
            assert!(cat.size.iter().all(|&s| s > 0.0), "{}", cat.name);
        }
        assert!(c.categories().len() >= 60);
        assert_eq!(c.similarity("desk", "table"), 0.5);
        assert_eq!(c.similarity("desk", "desk"), 1.0);
        assert_eq!(c.similarity("desk", "bed"), 0.0);
    }
}
