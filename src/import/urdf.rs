//! The robot from its URDF: two moving links joined by a `spherical` joint
//! (pyBullet's ball, catflip's no-twist export) or by two `revolute` /
//! `continuous` joints through a light cross link (the universal joint).
//! Links fixed to a half (`fixed` joints: a battery, legs) join its rigid body.

use super::xml::{self, number, numbers, site, vec3};
use super::{Imported, Link, Part, Pose, assemble};
use crate::error::Result;
use roxmltree::Node;
use std::collections::HashMap;

/// A cross link heavier than this fraction of the lighter half is refused:
/// the model's cross is massless, and its error grows linearly with the
/// fraction (catflip's own export writes 1e-8).
pub const CROSS_MAX_FRACTION: f64 = 1e-4;

struct LinkData<'a> {
    node: Node<'a, 'a>,
    part: Part,
}

struct JointData<'a> {
    node: Node<'a, 'a>,
    kind: String,
    parent: String,
    child: String,
    origin: Pose,
    axis: nalgebra::Vector3<f64>,
    effort: Option<f64>,
    velocity: Option<f64>,
    /// A revolute joint's range `(lower, upper)`, rad.
    range: Option<(f64, f64)>,
}

fn origin(node: &Node, file: &str) -> Result<Pose> {
    match node.children().find(|c| c.has_tag_name("origin")) {
        None => Ok(Pose::identity()),
        Some(o) => Ok(Pose {
            r: xml::rpy(&numbers(&o, "rpy", 3, Some(&[0.0; 3]), file)?),
            p: vec3(&numbers(&o, "xyz", 3, Some(&[0.0; 3]), file)?),
        }),
    }
}

fn inertial(link: &Node, file: &str) -> Result<Part> {
    let Some(i) = link.children().find(|c| c.has_tag_name("inertial")) else {
        return Ok(Part::empty());
    };
    let pose = origin(&i, file)?;
    // (URDF requires it; without it the link's inertia would have no mass)
    let mass = match i.children().find(|c| c.has_tag_name("mass")) {
        Some(m) => xml::mass(&m, "value", file)?,
        None => {
            return Err(site(&i).error(
                file,
                "an <inertial> without <mass>: give <mass value=\"...\"/> in kg",
            ));
        }
    };
    // (URDF requires it, with all six moments, as urdfdom reads it: a
    // missing one taken as 0 made a link a point mass, or a typo `ix` a body
    // that breaks the triangle inequality, named at its link)
    let inertia = match i.children().find(|c| c.has_tag_name("inertia")) {
        Some(t) => {
            let g = |a: &str| {
                if t.attribute(a).is_none() {
                    return Err(site(&t).error(
                        file,
                        format!(
                            "needs the attribute `{a}` (kg m^2): an <inertia> gives all six of ixx, ixy, ixz, iyy, iyz, izz (0 for a product that is zero)"
                        ),
                    ));
                }
                number(&t, a, None, file)
            };
            xml::tensor(
                g("ixx")?,
                g("iyy")?,
                g("izz")?,
                g("ixy")?,
                g("ixz")?,
                g("iyz")?,
            )
        }
        None => {
            return Err(site(&i).error(
                file,
                "an <inertial> without <inertia>: give <inertia ixx=\"...\" ixy=\"...\" ixz=\"...\" iyy=\"...\" iyz=\"...\" izz=\"...\"/> in kg m^2 about the <inertial>'s origin",
            ));
        }
    };
    Ok(Part {
        mass,
        com: nalgebra::Vector3::zeros(),
        inertia,
    }
    .moved(&pose))
}

fn link_name<'a>(joint: &Node<'a, 'a>, tag: &str, file: &str) -> Result<String> {
    joint
        .children()
        .find(|c| c.has_tag_name(tag))
        .and_then(|c| c.attribute("link"))
        .map(str::to_string)
        .ok_or_else(|| site(joint).error(file, format!("needs <{tag} link=\"...\"/>")))
}

/// A joint limit's `effort` or `velocity`, which catflip reads as the
/// motor's `key`: none when absent or 0 (exporters write 0 for "not
/// given"); a negative one is an error at its element, naming the key that
/// replaces it.
fn motor_limit(l: &Node, attr: &str, key: &str, file: &str) -> Result<Option<f64>> {
    let x = number(l, attr, Some(f64::NAN), file)?;
    if x < 0.0 {
        return Err(site(l).error(
            file,
            format!(
                "{attr}=\"{x}\" is negative: give the motor's limit (> 0; 0 or none means not given), or remove it and set {key} in the config"
            ),
        ));
    }
    Ok(Some(x).filter(|x| x.is_finite() && *x > 0.0))
}

/// Reads `text` (the file `file`).
pub fn read(text: &str, file: &str) -> Result<Imported> {
    let doc = xml::parse(text, file)?;
    let robot = doc.root_element();
    if !robot.has_tag_name("robot") {
        return Err(site(&robot).error(file, "a URDF's root element is <robot>"));
    }
    let mut links: HashMap<String, LinkData> = HashMap::new();
    let mut order = vec![];
    for n in robot.children().filter(|c| c.has_tag_name("link")) {
        let name = n
            .attribute("name")
            .ok_or_else(|| site(&n).error(file, "a link needs a name"))?
            .to_string();
        let part = inertial(&n, file)?;
        order.push(name.clone());
        links.insert(name, LinkData { node: n, part });
    }
    let mut joints = vec![];
    for n in robot.children().filter(|c| c.has_tag_name("joint")) {
        let kind = n.attribute("type").unwrap_or("").to_string();
        let limit = n.children().find(|c| c.has_tag_name("limit"));
        let j = JointData {
            node: n,
            parent: link_name(&n, "parent", file)?,
            child: link_name(&n, "child", file)?,
            origin: origin(&n, file)?,
            axis: match n.children().find(|c| c.has_tag_name("axis")) {
                Some(a) => vec3(&xml::direction(&a, "xyz", 3, Some(&[1.0, 0.0, 0.0]), file)?),
                None => nalgebra::Vector3::x(),
            },
            effort: limit
                .map(|l| motor_limit(&l, "effort", "limits.max_torque", file))
                .transpose()?
                .flatten(),
            velocity: limit
                .map(|l| motor_limit(&l, "velocity", "limits.max_speed", file))
                .transpose()?
                .flatten(),
            // a revolute joint's range when the file gives one (URDF
            // defaults a missing end to 0, but files that give only
            // `effort` and `velocity` mean no range); a continuous joint
            // has none
            range: match (kind.as_str(), limit) {
                ("revolute", Some(l))
                    if l.attribute("lower").is_some() || l.attribute("upper").is_some() =>
                {
                    Some((
                        number(&l, "lower", Some(0.0), file)?,
                        number(&l, "upper", Some(0.0), file)?,
                    ))
                }
                _ => None,
            },
            kind,
        };
        for l in [&j.parent, &j.child] {
            if !links.contains_key(l) {
                return Err(site(&n).error(
                    file,
                    format!("names the link `{l}`, which the file does not have"),
                ));
            }
        }
        match j.kind.as_str() {
            "fixed" | "revolute" | "continuous" | "spherical" => {}
            "prismatic" => {
                return Err(site(&n).error(
                    file,
                    "a prismatic joint: catflip's halves only turn about the joint",
                ));
            }
            "floating" | "planar" => {
                return Err(site(&n).error(
                    file,
                    format!(
                        "a {} joint between links: catflip's halves are joined at one point",
                        j.kind
                    ),
                ));
            }
            other => {
                return Err(site(&n).error(file, format!("unknown joint type `{other}` (URDF has revolute, continuous, prismatic, fixed, floating, planar; pyBullet adds spherical)")));
            }
        }
        joints.push(j);
    }
    for (k, j) in joints.iter().enumerate() {
        if let Some(o) = joints[..k].iter().find(|o| o.child == j.child) {
            return Err(site(&j.node).error(
                file,
                format!(
                    "the link `{}` is already the child of `{}`: a link has one parent",
                    j.child,
                    o.node.attribute("name").unwrap_or("?")
                ),
            ));
        }
        if j.child == j.parent {
            return Err(site(&j.node).error(file, "joins a link to itself"));
        }
    }
    // fold every fixed child into its parent, deepest first, carrying its joints along
    while let Some(k) = joints.iter().position(|j| {
        j.kind == "fixed"
            && !joints
                .iter()
                .any(|o| o.kind == "fixed" && o.parent == j.child)
    }) {
        let j = joints.remove(k);
        let child = links.remove(&j.child).expect("checked above");
        let parent = links.get_mut(&j.parent).ok_or_else(|| {
            site(&j.node).error(file, "its parent is fixed to its own child (a loop)")
        })?;
        parent.part = parent.part.plus(&child.part.moved(&j.origin));
        for o in joints.iter_mut().filter(|o| o.parent == j.child) {
            o.parent = j.parent.clone();
            o.origin = j.origin.then(&o.origin);
        }
    }
    if let Some(j) = joints.iter().find(|j| j.kind == "fixed") {
        return Err(site(&j.node).error(file, "the fixed joints form a loop"));
    }
    let moving: Vec<&String> = order.iter().filter(|n| links.contains_key(*n)).collect();
    let roots: Vec<&&String> = moving
        .iter()
        .filter(|n| !joints.iter().any(|j| &&j.child == *n))
        .collect();
    if moving.is_empty() {
        return Err(site(&robot).error(file, "no <link>: catflip needs the robot's two halves"));
    }
    if roots.len() != 1 {
        let name: &String = roots.get(1).map(|r| **r).unwrap_or(moving[0]);
        let n = &links[name];
        return Err(site(&n.node).error(
            file,
            format!(
                "the links form {} separate trees: catflip needs one robot of two halves",
                roots.len()
            ),
        ));
    }
    let root = (**roots[0]).clone();
    let limits = |js: &[&JointData]| {
        let min = |f: &dyn Fn(&JointData) -> Option<f64>| {
            js.iter()
                .filter_map(|j| f(j))
                .fold(None, |a: Option<f64>, x| Some(a.map_or(x, |a| a.min(x))))
        };
        (min(&|j| j.effort), min(&|j| j.velocity))
    };
    let third = |name: &str| {
        let n = &links[name];
        site(&n.node).error(
            file,
            "a third moving link: catflip models two rigid halves and a joint (fix it to a half with a fixed joint, or remove it)",
        )
    };
    let from_root: Vec<&JointData> = joints.iter().filter(|j| j.parent == root).collect();
    if from_root.len() != 1 {
        return Err(match from_root.get(1) {
            Some(j) => third(&j.child),
            None => site(&links[&root].node).error(
                file,
                "no joint moves anything from this root link: catflip needs two halves",
            ),
        });
    }
    let first = from_root[0];
    let rear = (links[&root].part, site(&links[&root].node));
    let (front_name, link, used) = match first.kind.as_str() {
        "spherical" => (
            first.child.clone(),
            Link::Ball {
                point: first.origin.p,
            },
            vec![first],
        ),
        _ => {
            let cross = &first.child;
            let next: Vec<&JointData> = joints.iter().filter(|j| &j.parent == cross).collect();
            let second = match next.as_slice() {
                [s] if s.kind == "revolute" || s.kind == "continuous" => *s,
                [s] => {
                    return Err(site(&s.node).error(file, "after a revolute joint catflip needs a second revolute joint (the universal joint's cross)"));
                }
                [] => {
                    return Err(site(&first.node).error(file, "one revolute joint bends in one plane only: catflip needs two (a universal joint through a light cross link) or a spherical joint"));
                }
                [_, s, ..] => return Err(third(&s.child)),
            };
            let lighter = links[&root].part.mass.min(links[&second.child].part.mass);
            let cm = links[cross].part.mass;
            // (a massless half is named as such when the halves are assembled)
            if lighter > 0.0 && cm > CROSS_MAX_FRACTION * lighter {
                return Err(site(&links[cross].node).error(
                    file,
                    format!(
                        "the universal joint's cross weighs {cm} kg, more than {CROSS_MAX_FRACTION:e} of a half: catflip's cross is massless (a third moving link it cannot model)"
                    ),
                ));
            }
            let t1 = first.origin;
            let t2 = t1.then(&second.origin);
            (
                second.child.clone(),
                Link::Hinges {
                    p1: t1.p,
                    a1: t1.r * first.axis,
                    p2: t2.p,
                    a2: t2.r * second.axis,
                    second: site(&second.node),
                },
                vec![first, second],
            )
        }
    };
    // front's pose in the rear's frame at q = 0
    let front_pose = used
        .iter()
        .fold(Pose::identity(), |acc, j| acc.then(&j.origin));
    if let Some(j) = joints.iter().find(|j| j.parent == front_name) {
        return Err(third(&j.child));
    }
    if let Some(extra) = moving
        .iter()
        .find(|n| ***n != root && ***n != front_name && !used.iter().any(|j| &j.child == **n))
    {
        return Err(third(extra));
    }
    let front = (
        links[&front_name].part.moved(&front_pose),
        site(&links[&front_name].node),
    );
    let (max_torque, max_speed) = limits(&used);
    let max_bend = bend_limit(&used, file)?;
    let (halves, joint) = assemble(file, rear, front, link)?;
    Ok(Imported {
        halves,
        joint,
        max_torque,
        max_speed,
        max_bend,
    })
}

/// A joint range's end in radians beyond which, up to 360, it reads as
/// degrees: a full turn (catflip's own exports write +-pi).
const DEGREES_SLIP: f64 = 2.0 * std::f64::consts::PI * (1.0 + 1e-9);

/// The largest bend every joint range allows, rad: each revolute joint
/// turns at least this far both ways (the disc inside their box, so a
/// design within it is within every range); `None` without a range. A range
/// that does not reach both sides of zero leaves no bend in one direction:
/// refused, naming the joint, and so is one typed in degrees.
fn bend_limit(used: &[&JointData], file: &str) -> Result<Option<f64>> {
    let mut least: Option<f64> = None;
    for j in used {
        let Some((lower, upper)) = j.range else {
            continue;
        };
        if !(lower < 0.0 && upper > 0.0) {
            return Err(site(&j.node).error(
                file,
                format!(
                    "the joint's range [{lower}, {upper}] rad does not reach both sides of the straight body: catflip's halves bend both ways (give lower < 0 < upper, or a continuous joint)"
                ),
            ));
        }
        // URDF gives radians; an end past a full turn but not past 360
        // is a range typed in degrees, which would bound nothing (wider
        // than any fold); further ends are the files' "no limit"
        if let Some(end) = [lower, upper]
            .into_iter()
            .find(|e| (DEGREES_SLIP..=360.0).contains(&e.abs()))
        {
            return Err(site(&j.node).error(
                file,
                format!(
                    "the joint's range [{lower}, {upper}] rad goes past a full turn: URDF limits are in radians, so degrees typed there bound nothing ({end} deg is {:.4} rad; give the range in radians, or a continuous joint for none)",
                    end.to_radians()
                ),
            ));
        }
        let b = (-lower).min(upper);
        least = Some(least.map_or(b, |l| l.min(b)));
    }
    Ok(least)
}
