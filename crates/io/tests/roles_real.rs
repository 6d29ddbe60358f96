//! Joint roles on the real rigs in `../shared/data` (issue 42): CMU BVH (both cgspeed releases) and
//! ASF by name, every Character Creator take by name, and each of them again with bare names (by
//! shape, which must pick the same joints), CesiumMan's skin by shape, and Kenney's one-segment
//! limbs refused with the roles they lack. Skipped without data.

use glam::{DQuat, DVec3};
use inbetween_core::roles::fixtures::{bare, with_skeleton};
use inbetween_core::roles::{find_motion_roles, How, Role, RoleOverrides, Roles, RolesError, Scheme, Side};
use inbetween_core::{Joint, Motion, Skeleton};
use inbetween_io::data::with_shared_data;
use std::path::Path;

fn roles(m: &Motion, what: &str) -> Roles {
    find_motion_roles(m, &RoleOverrides::default()).unwrap_or_else(|e| panic!("{what}: {e}"))
}

fn name(m: &Motion, r: &Roles, role: Role) -> String {
    m.skeleton.joint(r.joint(role)).name.clone()
}

/// By name as `scheme`, with these joints, and the same joints again by shape on bare names.
fn check(m: &Motion, what: &str, scheme: Scheme, expect: &[(Role, &str)]) {
    let r = roles(m, what);
    assert_eq!(r.scheme, Some(scheme), "{what}");
    for (role, joint) in expect {
        assert_eq!(name(m, &r, *role), *joint, "{what}: {role}");
        assert_eq!(r.how(*role), Some(How::Name(scheme)), "{what}: {role}");
    }
    let b = with_skeleton(m, bare(&m.skeleton));
    let by_shape = roles(&b, &format!("{what}, bare names"));
    for role in Role::ALL.into_iter().filter(|r| r.required()) {
        assert_eq!(
            by_shape.get(role),
            r.get(role),
            "{what}: {role} by shape is {} (by name {})",
            by_shape.get(role).map(|j| m.skeleton.joint(j).name.clone()).unwrap_or_default(),
            name(m, &r, role)
        );
    }
    println!("{what}: {} by name; by shape on bare names, confidence {:.2}", scheme.label(), by_shape.confidence());
}

const L: Side = Side::Left;
const R: Side = Side::Right;

#[test]
fn cmu_takes_by_name_and_by_shape() {
    with_shared_data("mocap/cmu", |data| {
        let cmu = data.join("mocap/cmu");
        let m = inbetween_io::load_motion(&cmu.join("cgspeed/01_01.bvh")).unwrap();
        let expect = [
            (Role::Hips, "Hips"),
            (Role::UpperArm(L), "LeftArm"),
            (Role::Forearm(R), "RightForeArm"),
            (Role::Thigh(L), "LeftUpLeg"),
            (Role::Foot(R), "RightFoot"),
            (Role::Head, "Head"),
        ];
        check(&m, "cgspeed/01_01.bvh", Scheme::CmuBvh, &expect);
        let m = inbetween_io::load_motion(&cmu.join("cgspeed/131_01.bvh")).unwrap();
        let expect = [
            (Role::Clavicle(L), "LeftCollar"),
            (Role::UpperArm(L), "LeftShoulder"),
            (Role::Hand(R), "RightWrist"),
            (Role::Thigh(R), "RightHip"),
            (Role::Shin(L), "LeftKnee"),
            (Role::Toe(L), "LeftToe"),
        ];
        check(&m, "cgspeed/131_01.bvh", Scheme::CmuMax, &expect);
        let asf = cmu.join("asf_amc");
        let m = inbetween_io::read_asf_amc(&asf.join("01.asf"), &asf.join("01_01.amc")).unwrap();
        let expect = [
            (Role::Hips, "root"),
            (Role::UpperArm(R), "rhumerus"),
            (Role::Hand(L), "lwrist"),
            (Role::Thigh(L), "lfemur"),
            (Role::Toe(R), "rtoes"),
        ];
        check(&m, "asf_amc/01.asf", Scheme::CmuAsf, &expect);
    });
}

#[test]
fn every_character_creator_take_by_name_and_by_shape() {
    with_shared_data("mocap/cmu/iclone_cc", |data| {
        let dir = data.join("mocap/cmu/iclone_cc");
        let mut files: Vec<_> = std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()).collect();
        files.retain(|p| p.extension().is_some_and(|e| e == "bvh"));
        files.sort();
        assert!(!files.is_empty());
        for f in files {
            let m = inbetween_io::load_motion(&f).unwrap();
            // Two frames are enough for the roles: frame 0, the T-pose, is where the shape is read.
            let m = m.crop(0, 2).unwrap();
            let expect = [
                (Role::Hips, "CC_Base_Hip"),
                (Role::Clavicle(L), "CC_Base_L_Clavicle"),
                (Role::UpperArm(R), "CC_Base_R_Upperarm"),
                (Role::Hand(L), "CC_Base_L_Hand"),
                (Role::Shin(R), "CC_Base_R_Calf"),
                (Role::Toe(L), "CC_Base_L_ToeBase"),
                (Role::Head, "CC_Base_Head"),
            ];
            check(&m, &f.file_name().unwrap().to_string_lossy(), Scheme::CharacterCreator, &expect);
        }
    });
}

/// The skin's joints of a `.glb` as a skeleton in its bind pose (global positions from the nodes'
/// translations, rotations and scales), with their own names; joints outside the skin are skipped.
fn skin_skeleton(path: &Path) -> Skeleton {
    let bytes = std::fs::read(path).unwrap();
    let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + len]).unwrap();
    let nodes = json["nodes"].as_array().unwrap();
    let v = |n: &serde_json::Value, key: &str, default: &[f64]| -> Vec<f64> {
        n[key].as_array().map(|a| a.iter().map(|x| x.as_f64().unwrap()).collect()).unwrap_or(default.to_vec())
    };
    let mut parent = vec![None; nodes.len()];
    for (i, n) in nodes.iter().enumerate() {
        for c in n["children"].as_array().into_iter().flatten() {
            parent[c.as_u64().unwrap() as usize] = Some(i);
        }
    }
    let local = |i: usize| {
        let (t, r, s) = (
            v(&nodes[i], "translation", &[0.0; 3]),
            v(&nodes[i], "rotation", &[0.0, 0.0, 0.0, 1.0]),
            v(&nodes[i], "scale", &[1.0; 3]),
        );
        glam::DMat4::from_scale_rotation_translation(
            DVec3::new(s[0], s[1], s[2]),
            DQuat::from_xyzw(r[0], r[1], r[2], r[3]),
            DVec3::new(t[0], t[1], t[2]),
        )
    };
    let global = |mut i: usize| {
        let mut m = local(i);
        while let Some(p) = parent[i] {
            m = local(p) * m;
            i = p;
        }
        m.transform_point3(DVec3::ZERO)
    };
    let skin: Vec<usize> =
        json["skins"][0]["joints"].as_array().unwrap().iter().map(|j| j.as_u64().unwrap() as usize).collect();
    // Parents before children: order the skin's joints by depth.
    let depth = |mut i: usize| {
        let mut d = 0;
        while let Some(p) = parent[i] {
            d += 1;
            i = p;
        }
        d
    };
    let mut order = skin.clone();
    order.sort_by_key(|&j| depth(j));
    let mut joints: Vec<Joint> = Vec::new();
    for &n in &order {
        let mut p = parent[n];
        while let Some(q) = p.filter(|q| !order.contains(q)) {
            p = parent[q];
        }
        let parent_index = p.map(|q| order.iter().position(|&o| o == q).unwrap());
        let offset = global(n) - p.map(global).unwrap_or(DVec3::ZERO);
        joints.push(Joint {
            name: nodes[n]["name"].as_str().unwrap_or("").to_string(),
            parent: parent_index,
            offset,
            channels: Vec::new(),
            end_site: None,
        });
    }
    Skeleton::new(joints).unwrap()
}

#[test]
fn cesium_man_by_shape_and_kenney_refused() {
    with_shared_data("assets/gltf_samples/CesiumMan.glb", |data| {
        let s = skin_skeleton(&data.join("assets/gltf_samples/CesiumMan.glb"));
        let m = Motion::new(s.clone(), 1.0 / 30.0, Vec::new()).unwrap();
        let r = roles(&m, "CesiumMan");
        let n = |role| s.joint(r.joint(role)).name.clone();
        println!("CesiumMan:\n{r}");
        assert_eq!(r.how(Role::Hand(L)), Some(How::Shape));
        // Its joints name their side (`_L_`, `_R`) though no scheme names the roles: the shape's sides agree.
        for side in Side::BOTH {
            let tag = if side == L { "_L" } else { "_R" };
            for role in [Role::UpperArm(side), Role::Hand(side), Role::Thigh(side), Role::Foot(side)] {
                assert!(n(role).contains(tag), "{role}: {}", n(role));
            }
        }
        assert_eq!(n(Role::Thigh(L)), "leg_joint_L_1");
        assert_eq!(n(Role::Foot(R)), "leg_joint_R_3");
        assert_eq!(r.get(Role::Toe(L)).map(|j| s.joint(j).name.as_str()), Some("leg_joint_L_5"));
        assert_eq!(n(Role::UpperArm(R)), "Skeleton_arm_joint_R");
        assert!(r.confidence() >= 0.7, "{}", r.confidence());
        // Kenney's blocky characters: one segment per limb, no elbows or knees.
        let kenney = data.join("assets/kenney_blocky_characters/character-a.glb");
        let bytes = std::fs::read(&kenney).unwrap();
        let len = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        let json: serde_json::Value = serde_json::from_slice(&bytes[20..20 + len]).unwrap();
        let names: Vec<&str> = json["nodes"].as_array().unwrap().iter().filter_map(|n| n["name"].as_str()).collect();
        let mut joints: Vec<Joint> = Vec::new();
        for (i, name) in names.iter().enumerate().skip(1) {
            let t = json["nodes"][i]["translation"]
                .as_array()
                .map(|a| DVec3::new(a[0].as_f64().unwrap(), a[1].as_f64().unwrap(), a[2].as_f64().unwrap()))
                .unwrap_or(DVec3::ZERO);
            joints.push(Joint {
                name: name.to_string(),
                parent: (i > 1).then_some(0),
                offset: t,
                channels: Vec::new(),
                end_site: None,
            });
        }
        let s = Skeleton::new(joints).unwrap();
        let e = inbetween_core::roles::find_roles(&s, &RoleOverrides::default()).unwrap_err();
        println!("Kenney character-a: {e}");
        assert!(matches!(e, RolesError::Missing { .. }), "{e}");
        let text = e.to_string();
        assert!(text.contains("left_forearm") && text.contains("`roles`"), "{text}");
    });
}
