//! The robot from its MJCF: one body tree in `<worldbody>` whose root (free
//! or not) is the rear half; the front half hangs on it by a `ball` joint,
//! by two `hinge` joints in one body, or by a hinge through a light cross
//! body and a second hinge. Bodies without joints join their parent's rigid
//! body. Inertia comes from each body's `<inertial>` (catflip does not
//! derive it from geoms).

use super::urdf::CROSS_MAX_FRACTION;
use super::xml::{self, numbers, site, vec3};
use super::{Imported, Link, Part, Pose, Site, assemble};
use crate::error::Result;
use nalgebra::{Matrix3, Vector3};
use roxmltree::Node;

struct Angles {
    radian: bool,
    seq: Vec<char>,
}

/// A body with its jointless descendants folded in (frame: the body's).
struct Group<'a> {
    node: Node<'a, 'a>,
    part: Part,
    /// Bodies with joints below it, and their poses in this body's frame.
    moving: Vec<(Node<'a, 'a>, Pose)>,
}

fn orientation(n: &Node, angles: &Angles, file: &str) -> Result<Matrix3<f64>> {
    let given: Vec<&str> = ["quat", "axisangle", "euler", "xyaxes", "zaxis"]
        .into_iter()
        .filter(|a| n.attribute(*a).is_some())
        .collect();
    if given.len() > 1 {
        // (MuJoCo refuses it too: which one holds is not said)
        return Err(site(n).error(
            file,
            format!(
                "{} give its orientation twice: give one",
                given.join(" and ")
            ),
        ));
    }
    for bad in ["xyaxes", "zaxis"] {
        if n.attribute(bad).is_some() {
            return Err(site(n).error(
                file,
                format!(
                    "orientation by `{bad}` is not read by catflip: give quat, euler or axisangle"
                ),
            ));
        }
    }
    let unit = if angles.radian {
        1.0
    } else {
        std::f64::consts::PI / 180.0
    };
    if n.attribute("quat").is_some() {
        return Ok(xml::quat(&xml::direction(n, "quat", 4, None, file)?));
    }
    if n.attribute("axisangle").is_some() {
        let v = numbers(n, "axisangle", 4, None, file)?;
        if v[..3].iter().all(|x| *x == 0.0) {
            return Err(site(n).error(
                file,
                "attribute `axisangle` has an all-zero axis: it must give a direction",
            ));
        }
        return Ok(xml::axis_angle(&v[..3], v[3] * unit));
    }
    if n.attribute("euler").is_some() {
        let v = numbers(n, "euler", 3, None, file)?;
        let mut r = Matrix3::identity();
        for (k, ch) in angles.seq.iter().enumerate() {
            let axis = match ch.to_ascii_lowercase() {
                'x' => [1.0, 0.0, 0.0],
                'y' => [0.0, 1.0, 0.0],
                _ => [0.0, 0.0, 1.0],
            };
            let e = xml::axis_angle(&axis, v[k] * unit);
            // lower case: axes that move with the frame; upper case: fixed axes
            r = if ch.is_ascii_lowercase() {
                r * e
            } else {
                e * r
            };
        }
        return Ok(r);
    }
    Ok(Matrix3::identity())
}

fn pose(n: &Node, angles: &Angles, file: &str) -> Result<Pose> {
    Ok(Pose {
        r: orientation(n, angles, file)?,
        p: vec3(&numbers(n, "pos", 3, Some(&[0.0; 3]), file)?),
    })
}

fn joints<'a>(body: &Node<'a, 'a>) -> Vec<Node<'a, 'a>> {
    body.children()
        .filter(|c| c.has_tag_name("joint") || c.has_tag_name("freejoint"))
        .collect()
}

fn group<'a>(
    body: Node<'a, 'a>,
    angles: &Angles,
    from_geom: bool,
    file: &str,
) -> Result<Group<'a>> {
    let mut part = match body.children().find(|c| c.has_tag_name("inertial")) {
        Some(i) => {
            let pose = pose(&i, angles, file)?;
            let inertia = if i.attribute("fullinertia").is_some() {
                let v = numbers(&i, "fullinertia", 6, None, file)?;
                xml::tensor(v[0], v[1], v[2], v[3], v[4], v[5])
            } else {
                let v = numbers(&i, "diaginertia", 3, None, file)?;
                Matrix3::from_diagonal(&vec3(&v))
            };
            Part {
                mass: xml::mass(&i, "mass", file)?,
                com: Vector3::zeros(),
                inertia,
            }
            .moved(&pose)
        }
        None => {
            if from_geom && body.children().any(|c| c.has_tag_name("geom")) {
                return Err(site(&body).error(
                    file,
                    "a body with geoms and no <inertial>: catflip reads the mass and inertia from <inertial> (MuJoCo would derive them from the geoms)",
                ));
            }
            Part::empty()
        }
    };
    let mut moving = vec![];
    for child in body.children().filter(|c| c.has_tag_name("body")) {
        let p = pose(&child, angles, file)?;
        if joints(&child).is_empty() {
            let g = group(child, angles, from_geom, file)?;
            part = part.plus(&g.part.moved(&p));
            moving.extend(g.moving.into_iter().map(|(n, q)| (n, p.then(&q))));
        } else {
            moving.push((child, p));
        }
    }
    Ok(Group {
        node: body,
        part,
        moving,
    })
}

/// A body's joint: its type, position, axis and element.
type BodyJoint<'a> = (String, Vector3<f64>, Vector3<f64>, Node<'a, 'a>);

/// `(type, pos, axis, node)` of a body's joints.
fn hinge_or_ball<'a>(body: &Node<'a, 'a>, file: &str) -> Result<Vec<BodyJoint<'a>>> {
    let mut out = vec![];
    for j in joints(body) {
        let kind = if j.has_tag_name("freejoint") {
            "free".to_string()
        } else {
            j.attribute("type").unwrap_or("hinge").to_string()
        };
        match kind.as_str() {
            "hinge" | "ball" => {}
            "slide" => {
                return Err(site(&j).error(
                    file,
                    "a slide (prismatic) joint: catflip's halves only turn about the joint",
                ));
            }
            _ => {
                return Err(site(&j).error(
                    file,
                    format!(
                        "a {kind} joint inside the robot: catflip's halves are joined at one point"
                    ),
                ));
            }
        }
        let pos = vec3(&numbers(&j, "pos", 3, Some(&[0.0; 3]), file)?);
        let axis = vec3(&xml::direction(
            &j,
            "axis",
            3,
            Some(&[0.0, 0.0, 1.0]),
            file,
        )?);
        out.push((kind, pos, axis, j));
    }
    Ok(out)
}

/// Reads `text` (the file `file`).
pub fn read(text: &str, file: &str) -> Result<Imported> {
    let doc = xml::parse(text, file)?;
    let root = doc.root_element();
    if !root.has_tag_name("mujoco") {
        return Err(site(&root).error(file, "an MJCF's root element is <mujoco>"));
    }
    if let Some(inc) = root.descendants().find(|n| n.has_tag_name("include")) {
        return Err(site(&inc).error(
            file,
            "<include>: catflip reads one file; paste the included model in",
        ));
    }
    // defaults change elements that do not name them (a joint's type, a
    // body's mass): read as written they would give another robot
    if let Some(d) = root.descendants().find(|n| {
        n.has_tag_name("default")
            && n.children()
                .any(|c| c.is_element() && !c.has_tag_name("default"))
    }) {
        return Err(site(&d).error(
            file,
            "<default>: catflip does not read MJCF defaults; write the values on the elements",
        ));
    }
    if let Some(n) = root
        .descendants()
        .find(|n| n.attribute("class").is_some() || n.attribute("childclass").is_some())
    {
        return Err(site(&n).error(
            file,
            "`class`: catflip does not read MJCF default classes; write the values on the elements",
        ));
    }
    let compiler = root.children().find(|c| c.has_tag_name("compiler"));
    let angles = Angles {
        radian: compiler.and_then(|c| c.attribute("angle")) == Some("radian"),
        seq: compiler
            .and_then(|c| c.attribute("eulerseq"))
            .unwrap_or("xyz")
            .chars()
            .collect(),
    };
    let from_geom = compiler.and_then(|c| c.attribute("inertiafromgeom")) != Some("false");
    let world = root
        .children()
        .find(|c| c.has_tag_name("worldbody"))
        .ok_or_else(|| site(&root).error(file, "no <worldbody>"))?;
    let tops: Vec<Node> = world
        .children()
        .filter(|c| c.has_tag_name("body"))
        .collect();
    let top = match tops.as_slice() {
        [t] => *t,
        [] => {
            return Err(site(&world).error(file, "no <body>: catflip needs the robot's two halves"));
        }
        [_, t, ..] => {
            return Err(site(t).error(
                file,
                "a second body tree in <worldbody>: catflip needs one robot of two halves",
            ));
        }
    };
    for j in joints(&top) {
        let free = j.has_tag_name("freejoint") || j.attribute("type") == Some("free");
        if !free {
            return Err(site(&j).error(
                file,
                "the root body's joints: catflip's robot falls freely (a <freejoint/> or none)",
            ));
        }
    }
    let rear = group(top, &angles, from_geom, file)?;
    let third = |n: &Node| {
        site(n).error(file, "a third moving body: catflip models two rigid halves and a joint (remove its joints to fix it to a half)")
    };
    let (child, child_pose) =
        match rear.moving.as_slice() {
            [c] => *c,
            [] => return Err(site(&top).error(
                file,
                "nothing moves relative to this body: catflip needs two halves joined by a joint",
            )),
            [_, c, ..] => return Err(third(&c.0)),
        };
    let cj = hinge_or_ball(&child, file)?;
    let mut used = vec![];
    let (front, front_pose, link) = match cj.as_slice() {
        [(k, p, _, n)] if k == "ball" => {
            used.push(*n);
            let g = group(child, &angles, from_geom, file)?;
            (
                g,
                child_pose,
                Link::Ball {
                    point: child_pose.point(p),
                },
            )
        }
        [(k1, p1, a1, n1), (k2, p2, a2, n2)] if k1 == "hinge" && k2 == "hinge" => {
            used.extend([*n1, *n2]);
            let g = group(child, &angles, from_geom, file)?;
            let link = Link::Hinges {
                p1: child_pose.point(p1),
                a1: child_pose.r * a1,
                p2: child_pose.point(p2),
                a2: child_pose.r * a2,
                second: site(n2),
            };
            (g, child_pose, link)
        }
        [(k, p1, a1, n1)] if k == "hinge" => {
            // a cross body: one hinge here, the second in its only moving child
            let cross = group(child, &angles, from_geom, file)?;
            let (next, next_pose) = match cross.moving.as_slice() {
                [c] => *c,
                [] => return Err(site(n1).error(file, "one hinge bends in one plane only: catflip needs two (a universal joint) or a ball joint")),
                [_, c, ..] => return Err(third(&c.0)),
            };
            let nj = hinge_or_ball(&next, file)?;
            let (p2, a2, n2) = match nj.as_slice() {
                [(k, p, a, n)] if k == "hinge" => (*p, *a, *n),
                _ => return Err(site(&next).error(file, "after the cross body's hinge catflip needs one hinge (the universal joint's second axis)")),
            };
            let lighter = rear
                .part
                .mass
                .min(group(next, &angles, from_geom, file)?.part.mass);
            // (a massless half is named as such when the halves are assembled)
            if lighter > 0.0 && cross.part.mass > CROSS_MAX_FRACTION * lighter {
                return Err(site(&child).error(file, format!(
                    "the universal joint's cross weighs {} kg, more than {CROSS_MAX_FRACTION:e} of a half: catflip's cross is massless (a third moving body it cannot model)",
                    cross.part.mass
                )));
            }
            used.extend([*n1, n2]);
            let fp = child_pose.then(&next_pose);
            let link = Link::Hinges {
                p1: child_pose.point(p1),
                a1: child_pose.r * a1,
                p2: fp.point(&p2),
                a2: fp.r * a2,
                second: site(&n2),
            };
            (group(next, &angles, from_geom, file)?, fp, link)
        }
        _ => {
            return Err(site(&child).error(
                file,
                "catflip joins the halves by one ball joint or by two hinges (a universal joint)",
            ));
        }
    };
    if let Some((n, _)) = front.moving.first() {
        return Err(third(n));
    }
    let limit = max_torque(&root, &used, file)?;
    let rear_site: Site = site(&rear.node);
    let (halves, joint) = assemble(
        file,
        (rear.part, rear_site),
        (front.part.moved(&front_pose), site(&front.node)),
        link,
    )?;
    Ok(Imported {
        halves,
        joint,
        max_torque: limit,
        max_speed: None,
        max_bend: None,
    })
}

/// The smallest bound of `ctrlrange` / `forcerange` of the actuators on the joints `used`.
fn max_torque(root: &Node, used: &[Node], file: &str) -> Result<Option<f64>> {
    let names: Vec<&str> = used.iter().filter_map(|j| j.attribute("name")).collect();
    let mut best: Option<f64> = None;
    let Some(act) = root.children().find(|c| c.has_tag_name("actuator")) else {
        return Ok(None);
    };
    let joints: Vec<&str> = root
        .descendants()
        .filter(|n| n.has_tag_name("joint"))
        .filter_map(|j| j.attribute("name"))
        .collect();
    for a in act.children().filter(|c| c.is_element()) {
        // (MuJoCo refuses an actuator on a joint the model does not have)
        if let Some(j) = a.attribute("joint")
            && !joints.contains(&j)
        {
            return Err(site(&a).error(file, format!("joint=\"{j}\" names no joint of the model")));
        }
        if !a.attribute("joint").is_some_and(|j| names.contains(&j)) {
            continue;
        }
        for (range, limited) in [("ctrlrange", "ctrllimited"), ("forcerange", "forcelimited")] {
            if a.attribute(range).is_none() || a.attribute(limited) == Some("false") {
                continue;
            }
            let v = numbers(&a, range, 2, None, file)?;
            if v[0] > v[1] {
                return Err(site(&a).error(
                    file,
                    format!(
                        "{range} = \"{} {}\" has its lower bound above its upper one",
                        v[0], v[1]
                    ),
                ));
            }
            let b = v[0].abs().max(v[1].abs());
            best = Some(best.map_or(b, |x| x.min(b)));
        }
    }
    Ok(best)
}
