//! Joint roles on every naming scheme, on bare names (shape only), on reordered, turned and
//! detailed skeletons, and refusals of non-humanoids (issue 42).

use inbetween_core::procedural::{gait, standard_skeleton, GaitParams};
use inbetween_core::roles::fixtures::{bare, chain, quadruped, renamed, reordered, turned, with_extras};
use inbetween_core::roles::{find_roles, How, Role, RoleOverrides, Roles, RolesError, Scheme, Side};
use inbetween_core::{Joint, Skeleton};

fn roles(s: &Skeleton) -> Roles {
    find_roles(s, &RoleOverrides::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// Role → joint index for every role `r` finds.
fn indices(r: &Roles) -> Vec<(Role, usize)> {
    r.roles.iter().map(|(role, a)| (*role, a.joint)).collect()
}

fn standard() -> Skeleton {
    standard_skeleton()
}

#[test]
fn the_standard_skeleton_by_name_has_every_role_where_expected() {
    let s = standard();
    let r = roles(&s);
    let name = |role: Role| s.joint(r.joint(role)).name.as_str();
    assert_eq!(r.scheme, Some(Scheme::CmuBvh));
    assert_eq!(name(Role::Hips), "Hips");
    assert_eq!(name(Role::Head), "Head");
    assert_eq!(name(Role::UpperArm(Side::Left)), "LeftArm");
    assert_eq!(name(Role::Clavicle(Side::Right)), "RightShoulder");
    assert_eq!(name(Role::Thigh(Side::Right)), "RightUpLeg");
    assert_eq!(name(Role::Toe(Side::Left)), "LeftToeBase");
    assert_eq!(name(Role::Chest), "Spine1");
    assert_eq!(name(Role::Spine), "LowerBack");
    assert_eq!(name(Role::Neck), "Neck");
    let spine: Vec<&str> = r.spine.iter().map(|&j| s.joint(j).name.as_str()).collect();
    assert_eq!(spine, ["LowerBack", "Spine", "Spine1"]);
    let neck: Vec<&str> = r.neck.iter().map(|&j| s.joint(j).name.as_str()).collect();
    assert_eq!(neck, ["Neck", "Neck1"]);
    assert_eq!(r.how(Role::Chest), Some(How::Chain));
    assert_eq!(r.confidence(), 1.0);
    assert_eq!(s.joint(r.fingertip(&s, Side::Left).unwrap()).name, "LeftHandIndex1");
}

#[test]
fn every_scheme_names_the_same_joints_with_sides_in_any_case() {
    for base in [standard(), with_extras(&standard())] {
        let expected = indices(&roles(&base));
        for scheme in Scheme::ALL {
            let s = renamed(&base, scheme);
            let r = roles(&s);
            let want = match scheme {
                // Same names as HumanIK: told apart only by CMU's extra joints, absent here.
                Scheme::CmuBvh => Scheme::HumanIk,
                other => other,
            };
            assert_eq!(
                r.scheme,
                Some(want),
                "{scheme:?}: {:?}",
                s.joints().iter().map(|j| &j.name).collect::<Vec<_>>()
            );
            assert_eq!(indices(&r), expected, "{scheme:?}");
            for (role, a) in &r.roles {
                if role.required() {
                    assert_eq!(a.how, How::Name(want), "{scheme:?} {role}");
                }
            }
            // Upper and lower case, and another namespace, change nothing.
            for recase in [str::to_ascii_uppercase as fn(&str) -> String, str::to_ascii_lowercase] {
                let joints: Vec<Joint> = s
                    .joints()
                    .iter()
                    .map(|j| Joint { name: recase(&j.name).replace("MIXAMORIG:", "mixamorig1:"), ..j.clone() })
                    .collect();
                let Ok(other) = Skeleton::new(joints) else { continue };
                assert_eq!(indices(&roles(&other)), expected, "{scheme:?} recased: {:?}", other.joint(5).name);
            }
        }
    }
}

#[test]
fn the_shape_alone_finds_the_same_joints_on_bare_names() {
    for base in [standard(), with_extras(&standard())] {
        let expected = indices(&roles(&base));
        let r = roles(&bare(&base));
        assert_eq!(r.scheme, None);
        assert_eq!(indices(&r), expected);
        assert_eq!(r.how(Role::Hand(Side::Left)), Some(How::Shape));
        // Toes and a wide stance settle the sides; the head is the end of its chain (0.9).
        assert!((r.confidence() - 0.9).abs() < 1e-9, "{}", r.confidence());
    }
}

#[test]
fn sides_come_from_the_rest_pose_not_the_file_order_nor_the_facing() {
    let m = gait(&GaitParams { frames: 3, ..GaitParams::walk() });
    let moved = reordered(&m);
    let s = &moved.skeleton;
    assert_ne!(s.joint(1).name, m.skeleton.joint(1).name, "right side first now: {}", s.joint(1).name);
    for sk in [s.clone(), turned(s)] {
        let r = roles(&bare(&sk));
        for (role, a) in &r.roles {
            let by_name = roles(&sk).get(*role);
            assert_eq!(Some(a.joint), by_name, "{role}: {} by shape", sk.joint(a.joint).name);
        }
    }
}

#[test]
fn without_toes_the_character_is_taken_to_face_plus_z_with_less_confidence() {
    let (s, _) = standard().filter(|_, j| !j.name.contains("Toe"));
    let r = roles(&bare(&s));
    assert_eq!(r.get(Role::Toe(Side::Left)), None);
    assert_eq!(s.joint(r.joint(Role::Foot(Side::Left))).name, "LeftFoot");
    assert!((r.confidence() - 0.6).abs() < 1e-9, "{}", r.confidence());
    assert!(r.notes.iter().any(|n| n.contains("+Z")), "{:?}", r.notes);
    assert!(r.to_string().contains("shape, confidence 0.60"), "{r}");
}

#[test]
fn non_humanoids_are_refused_naming_what_is_missing_and_the_roles_file() {
    for s in [quadruped(), chain()] {
        let e = find_roles(&s, &RoleOverrides::default()).unwrap_err();
        let text = e.to_string();
        assert!(matches!(e, RolesError::Missing { .. }), "{text}");
        assert!(text.contains("no joint found for hips") || text.contains("left_upper_arm"), "{text}");
        assert!(text.contains("`roles`") && text.contains("left_hand"), "{text}");
    }
    let text = find_roles(&quadruped(), &RoleOverrides::default()).unwrap_err().to_string();
    assert!(text.contains("not a standing humanoid"), "{text}");
}

#[test]
fn a_roles_file_wins_and_a_missing_joint_in_it_is_named() {
    let s = bare(&standard());
    let base = roles(&s);
    let mut o = RoleOverrides::default();
    // The clavicle given as the upper arm: the file wins over the shape.
    let clav = base.joint_clavicle();
    o.joints.insert(Role::UpperArm(Side::Left), s.joint(clav).name.clone());
    o.joints.insert(Role::Clavicle(Side::Left), s.joint(base.joint(Role::Hips) + 1).name.clone());
    let r = find_roles(&s, &o);
    // The hips' first child is not above the arm: the limb check refuses it, naming both.
    let text = r.unwrap_err().to_string();
    assert!(text.contains("not below") && text.contains("roles file"), "{text}");
    let mut o = RoleOverrides::default();
    o.joints.insert(Role::Head, "j14".into());
    let r = find_roles(&s, &o).unwrap();
    assert_eq!(r.how(Role::Head), Some(How::Override));
    assert_eq!(r.get(Role::Head), s.find("j14"));
    o.joints.insert(Role::Hand(Side::Left), "LeftHand".into());
    let e = find_roles(&s, &o).unwrap_err().to_string();
    assert!(e.contains("'LeftHand'") && e.contains("left_hand"), "{e}");
}

trait ClavicleOf {
    fn joint_clavicle(&self) -> usize;
}

impl ClavicleOf for Roles {
    fn joint_clavicle(&self) -> usize {
        self.get(Role::Clavicle(Side::Left)).expect("the standard skeleton has clavicles")
    }
}

#[test]
fn correspondence_maps_roles_chains_and_fingers_across_schemes() {
    use inbetween_core::roles::correspondence;
    let t = standard();
    let tr = roles(&t);
    // Renamed to Daz: every role and chain joint maps back to the same index; with detail the
    // hip links and the longest finger chain too; the thumb has no counterpart of the same name.
    let s = renamed(&t, Scheme::Daz);
    let sr = roles(&s);
    let plain = correspondence((&t, &tr), (&s, &sr), false);
    let detail = correspondence((&t, &tr), (&s, &sr), true);
    for (j, joint) in t.joints().iter().enumerate() {
        let n = joint.name.as_str();
        let expect_plain = tr.role_of(j).is_some() || tr.spine.contains(&j) || tr.neck.contains(&j);
        assert_eq!(plain[j].is_some(), expect_plain, "{n}");
        if expect_plain {
            assert_eq!(plain[j], Some(j), "{n}");
        }
        let expect_detail =
            expect_plain || n.contains("HipJoint") || n.contains("FingerBase") || n.contains("HandIndex");
        assert_eq!(detail[j], expect_detail.then_some(j), "{n}");
    }
    // Onto itself every joint maps to itself (by role, chain or name).
    let same = correspondence((&t, &tr), (&t, &tr), true);
    assert!(same.iter().enumerate().all(|(j, m)| *m == Some(j)), "{same:?}");
}
