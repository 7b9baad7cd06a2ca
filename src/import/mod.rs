//! The robot's own body: the `[body]` section of a config, given half by half
//! or read from the robot's URDF or MJCF (docs/configuration.md, `[body]`).
//!
//! Both files are read with `roxmltree`, a read-only XML tree that keeps
//! every element's position, so that what catflip cannot model is refused
//! with the element's name and line.

pub mod mjcf;
pub mod urdf;
mod xml;

use crate::error::{Error, Result};
use crate::model::{Halves, Joint, Rigid};
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// `[body]`: general rigid halves (docs/configuration.md).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct BodyConfig {
    /// A URDF of the robot, relative to the config file.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub urdf: Option<String>,
    /// An MJCF (MuJoCo XML) of the robot, relative to the config file.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mjcf: Option<String>,
    /// `[body.rear]`: the rear half A (with a file: values that replace the file's).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rear: Option<RigidConfig>,
    /// `[body.front]`: the front half B.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub front: Option<RigidConfig>,
    /// The halves the section resolves to ([`resolve`]).
    #[serde(skip)]
    pub halves: Option<Halves>,
    /// The `[limits]` keys the file gave (not typed in the config), so that
    /// a warning about one names the file.
    #[serde(skip)]
    pub file_limits: Vec<&'static str>,
}

/// One half in its own frame (parallel to the other half's in the straight cat).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(deny_unknown_fields)]
pub struct RigidConfig {
    /// kg.
    pub mass: Option<f64>,
    /// Centre of mass `[x, y, z]`, m.
    pub com: Option<[f64; 3]>,
    /// Inertia about the centre of mass, kg m^2: a 3 x 3 matrix or
    /// `[ixx, iyy, izz, ixy, ixz, iyz]`.
    #[serde(default, deserialize_with = "inertia_input")]
    pub inertia: Option<[[f64; 3]; 3]>,
    /// Joint position `[x, y, z]`, m.
    pub joint: Option<[f64; 3]>,
    /// The universal joint's motor axis on this half (rear: motor 1, default
    /// `[1, 0, 0]`; front: motor 2, default `[0, 1, 0]`).
    pub axis: Option<[f64; 3]>,
}

const INERTIA_FORMS: &str = "[[ixx, ixy, ixz], [ixy, iyy, iyz], [ixz, iyz, izz]] or [ixx, iyy, izz, ixy, ixz, iyz] (kg m^2, about the centre of mass)";

fn inertia_input<'de, D: serde::Deserializer<'de>>(
    d: D,
) -> std::result::Result<Option<[[f64; 3]; 3]>, D::Error> {
    #[derive(Deserialize)]
    #[serde(untagged)]
    enum Form {
        Matrix([[f64; 3]; 3]),
        Six([f64; 6]),
    }
    match Form::deserialize(d) {
        Ok(Form::Matrix(m)) => Ok(Some(m)),
        Ok(Form::Six([xx, yy, zz, xy, xz, yz])) => {
            Ok(Some([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]]))
        }
        Err(_) => Err(serde::de::Error::custom(format!(
            "inertia must be {INERTIA_FORMS}"
        ))),
    }
}

/// What a robot description gives: the halves, the joint and the motor limits.
#[derive(Debug, Clone, PartialEq)]
pub struct Imported {
    pub halves: Halves,
    pub joint: Joint,
    /// The smallest torque bound of the file's motors, N m (URDF `effort`,
    /// MJCF `ctrlrange` / `forcerange`).
    pub max_torque: Option<f64>,
    /// The smallest speed bound (URDF `velocity`), rad/s.
    pub max_speed: Option<f64>,
    /// The largest bend within every joint's range (URDF revolute `lower`
    /// and `upper`), rad.
    pub max_bend: Option<f64>,
}

/// Reads a robot description by its extension's kind.
pub fn read_file(path: &Path, kind: FileKind) -> Result<Imported> {
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| {
        invalid(
            &format!("body.{}", kind.key()),
            &name,
            format!("cannot read it ({e}); the path is relative to the config file"),
        )
    })?;
    match kind {
        FileKind::Urdf => urdf::read(&text, &name),
        FileKind::Mjcf => mjcf::read(&text, &name),
    }
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FileKind {
    Urdf,
    Mjcf,
}

impl FileKind {
    fn key(self) -> &'static str {
        match self {
            FileKind::Urdf => "urdf",
            FileKind::Mjcf => "mjcf",
        }
    }
}

fn invalid(key: &str, value: impl std::fmt::Display, expected: impl Into<String>) -> Error {
    Error::Invalid {
        key: key.into(),
        value: value.to_string(),
        expected: expected.into(),
    }
}

/// Resolves the config table's `[body]` in place, before it is parsed: the
/// halves (from the file, then the keys that replace its values), `[cat]`'s
/// cylinder keys filled with the halves' equivalent cylinders (scales and
/// drawings), `cat.joint` from the file, and the file's motor limits as
/// `[limits]` where the config sets none. `base` is the config's folder.
pub fn resolve(
    table: &mut toml::Table,
    base: &Path,
    origin: &str,
) -> Result<Option<(Halves, Vec<&'static str>)>> {
    let Some(body) = table.get("body").cloned() else {
        return Ok(None);
    };
    let body: BodyConfig = body
        .try_into()
        .map_err(|e: toml::de::Error| Error::ConfigParse {
            origin: origin.into(),
            message: format!("[body]: {}", e.message().trim()),
        })?;
    for (key, path) in [("body.urdf", &body.urdf), ("body.mjcf", &body.mjcf)] {
        if path.as_ref().is_some_and(|p| p.trim().is_empty()) {
            return Err(invalid(
                key,
                "\"\"",
                "an empty path: give the robot file's path, relative to the config file, or leave the key out",
            ));
        }
    }
    let file = match (&body.urdf, &body.mjcf) {
        (Some(_), Some(m)) => {
            return Err(invalid(
                "body.mjcf",
                format!("{m:?}"),
                "give one robot description: body.urdf or body.mjcf, not both",
            ));
        }
        (Some(u), None) => Some(read_file(&base.join(u), FileKind::Urdf)?),
        (None, Some(m)) => Some(read_file(&base.join(m), FileKind::Mjcf)?),
        (None, None) => None,
    };
    for (key, c) in [("body.rear", &body.rear), ("body.front", &body.front)] {
        if let Some(m) = c.as_ref().and_then(|c| c.mass)
            && !(m > 0.0 && m.is_finite())
        {
            return Err(invalid(
                &format!("{key}.mass"),
                m,
                "must be > 0 kg (a massless half has no dynamics)",
            ));
        }
    }
    let from_file = file.as_ref().map(|f| f.halves);
    let rear = half(
        "body.rear",
        body.rear.as_ref(),
        from_file.map(|h| h.rear),
        [1.0, 0.0, 0.0],
    )?;
    let front = half(
        "body.front",
        body.front.as_ref(),
        from_file.map(|h| h.front),
        [0.0, 1.0, 0.0],
    )?;
    let cat = table
        .entry("cat")
        .or_insert_with(|| toml::Value::Table(toml::Table::new()))
        .as_table_mut()
        .ok_or_else(|| invalid("cat", "not a table", "a table [cat]"))?;
    for key in ["mass", "length", "radius", "front"] {
        if let Some(v) = cat.get(key) {
            return Err(invalid(
                &format!("cat.{key}"),
                v,
                "[body] gives the halves, so the cylinders' cat.mass, cat.length, cat.radius and [cat.front] do not apply: leave them out of the config and its --set (cat.joint may stay); with [body], set (or sweep) its own keys, e.g. body.front.mass",
            ));
        }
    }
    let joint_given = match cat.get("joint") {
        Some(v) => Some(
            v.clone()
                .try_into::<Joint>()
                .map_err(|_| invalid("cat.joint", v, "no-twist or universal"))?,
        ),
        None => None,
    };
    let joint = match (&file, joint_given) {
        (Some(f), Some(j)) if f.joint != j => {
            return Err(invalid(
                "cat.joint",
                j.name(),
                format!(
                    "the robot description has a {} joint: remove cat.joint or make it {}",
                    f.joint.name(),
                    f.joint.name()
                ),
            ));
        }
        (Some(f), _) => f.joint,
        (None, j) => j.unwrap_or(Joint::NoTwist),
    };
    // a motor axis belongs to the universal joint: for the default no-twist
    // joint, or a robot file's, it would be dropped unseen (a cat.joint
    // named no-twist ignores it knowingly)
    if joint == Joint::NoTwist && joint_given != Some(Joint::NoTwist) {
        let fix = if file.is_some() {
            "a motor axis of the universal joint, but the robot description's joint is no-twist (a ball joint): leave the axes out"
        } else {
            "a motor axis of the universal joint, but no joint is named and the default is no-twist: set cat.joint = \"universal\" (or \"no-twist\" to ignore the axes)"
        };
        for (key, half) in [("rear", &body.rear), ("front", &body.front)] {
            if let Some(axis) = half.as_ref().and_then(|h| h.axis) {
                return Err(invalid(
                    &format!("body.{key}.axis"),
                    format!("{axis:?}"),
                    fix,
                ));
            }
        }
    }
    let halves = Halves { rear, front };
    if joint == Joint::Universal
        && let Some(p) = halves.axes_problem()
    {
        return Err(invalid("body.front.axis", format!("{:?}", front.axis), p));
    }
    let (er, ef) = (rear.equivalent_cylinder(), front.equivalent_cylinder());
    cat.insert("joint".into(), toml::Value::String(joint.name().into()));
    cat.insert("mass".into(), er.mass.into());
    cat.insert("length".into(), er.length.into());
    cat.insert("radius".into(), er.radius.into());
    let mut fr = toml::Table::new();
    fr.insert("mass".into(), ef.mass.into());
    fr.insert("length".into(), ef.length.into());
    fr.insert("radius".into(), ef.radius.into());
    cat.insert("front".into(), toml::Value::Table(fr));
    let mut from_file = Vec::new();
    if let Some(f) = &file {
        let limits = table
            .entry("limits")
            .or_insert_with(|| toml::Value::Table(toml::Table::new()))
            .as_table_mut()
            .ok_or_else(|| invalid("limits", "not a table", "a table [limits]"))?;
        // a joint range wider than the halves' own fold limit limits nothing
        let fold = crate::config::ranges::closest_theta_of(
            er.length.min(ef.length),
            er.radius + ef.radius,
        );
        let bend_deg = f
            .max_bend
            .filter(|&b| b < std::f64::consts::PI - fold)
            .map(f64::to_degrees);
        for (key, v) in [
            ("max_torque", f.max_torque),
            ("max_speed", f.max_speed),
            ("max_bend_deg", bend_deg),
        ] {
            if let Some(v) = v
                && !limits.contains_key(key)
            {
                limits.insert(key.into(), v.into());
                from_file.push(key);
            }
        }
    }
    Ok(Some((halves, from_file)))
}

/// One half from the file and the keys that replace its values; without a
/// file every key but `axis` is needed.
fn half(
    key: &str,
    cfg: Option<&RigidConfig>,
    file: Option<Rigid>,
    axis: [f64; 3],
) -> Result<Rigid> {
    let c = cfg.cloned().unwrap_or_default();
    let need = |name: &str| {
        invalid(
            &format!("{key}.{name}"),
            "missing",
            format!(
                "without body.urdf or body.mjcf each half needs mass, com, inertia and joint ({key}.{name})"
            ),
        )
    };
    let r = match file {
        Some(f) => Rigid {
            mass: c.mass.unwrap_or(f.mass),
            com: c.com.unwrap_or(f.com),
            inertia: c.inertia.unwrap_or(f.inertia),
            joint: c.joint.unwrap_or(f.joint),
            axis: c.axis.unwrap_or(f.axis),
        },
        None => Rigid {
            mass: c.mass.ok_or_else(|| need("mass"))?,
            com: c.com.ok_or_else(|| need("com"))?,
            inertia: c.inertia.ok_or_else(|| need("inertia"))?,
            joint: c.joint.ok_or_else(|| need("joint"))?,
            axis: c.axis.unwrap_or(axis),
        },
    };
    if let Some((field, why)) = r.problem_in() {
        // the value, and whether the user's key gave it (else the file did)
        let (value, given) = match field {
            "mass" => (format!("{}", r.mass), c.mass.is_some()),
            "com" => (format!("{:?}", r.com), c.com.is_some()),
            "joint" => (format!("{:?}", r.joint), c.joint.is_some()),
            "axis" => (format!("{:?}", r.axis), c.axis.is_some()),
            _ => (format!("{:?}", r.inertia), c.inertia.is_some()),
        };
        let source = if given {
            ""
        } else {
            " (from the robot description)"
        };
        return Err(invalid(
            &format!("{key}.{field}"),
            value,
            format!("{why}{source}"),
        ));
    }
    Ok(r)
}

/// A rigid transform: `x_parent = r x_child + p`.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Pose {
    pub r: Matrix3<f64>,
    pub p: Vector3<f64>,
}

impl Pose {
    pub fn identity() -> Pose {
        Pose {
            r: Matrix3::identity(),
            p: Vector3::zeros(),
        }
    }
    pub fn then(&self, child: &Pose) -> Pose {
        Pose {
            r: self.r * child.r,
            p: self.p + self.r * child.p,
        }
    }
    pub fn point(&self, x: &Vector3<f64>) -> Vector3<f64> {
        self.r * x + self.p
    }
}

/// Mass, centre of mass and inertia about it, in some frame.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Part {
    pub mass: f64,
    pub com: Vector3<f64>,
    pub inertia: Matrix3<f64>,
}

impl Part {
    pub fn empty() -> Part {
        Part {
            mass: 0.0,
            com: Vector3::zeros(),
            inertia: Matrix3::zeros(),
        }
    }
    /// The same part seen from the parent frame of `pose`.
    pub fn moved(&self, pose: &Pose) -> Part {
        Part {
            mass: self.mass,
            com: pose.point(&self.com),
            inertia: pose.r * self.inertia * pose.r.transpose(),
        }
    }
    /// Two parts fixed together (parallel-axis theorem), same frame.
    pub fn plus(&self, o: &Part) -> Part {
        let m = self.mass + o.mass;
        if m == 0.0 {
            return Part::empty();
        }
        let com = (self.com * self.mass + o.com * o.mass) / m;
        let shift = |p: &Part| {
            let d = p.com - com;
            p.mass * (Matrix3::identity() * d.dot(&d) - d * d.transpose())
        };
        Part {
            mass: m,
            com,
            inertia: self.inertia + shift(self) + o.inertia + shift(o),
        }
    }
}

/// Where a file's element is, for messages.
#[derive(Debug, Clone)]
pub(crate) struct Site {
    pub element: String,
    pub line: usize,
}

impl Site {
    pub fn error(&self, file: &str, message: impl Into<String>) -> Error {
        Error::Import {
            file: file.into(),
            line: self.line,
            element: self.element.clone(),
            message: message.into(),
        }
    }
}

/// How the front half hangs on the rear, all in the rear's frame at `q = 0`.
pub(crate) enum Link {
    /// A ball joint at `point` (catflip's no-twist joint).
    Ball { point: Vector3<f64> },
    /// Two hinges: motor 1 through `p1` about `a1` (on the rear), motor 2
    /// through `p2` about `a2` (on the front); `second` is motor 2's element.
    Hinges {
        p1: Vector3<f64>,
        a1: Vector3<f64>,
        p2: Vector3<f64>,
        a2: Vector3<f64>,
        second: Site,
    },
}

/// The halves from the two parts (both in the rear's frame at `q = 0`, the
/// frame both halves use) and the link between them.
pub(crate) fn assemble(
    file: &str,
    rear: (Part, Site),
    front: (Part, Site),
    link: Link,
) -> Result<(Halves, Joint)> {
    for (p, site) in [&rear, &front] {
        if p.mass <= 0.0 {
            return Err(site.error(
                file,
                "a moving link without mass: catflip's halves need their mass and inertia (give it an <inertial> with a mass above 0)",
            ));
        }
    }
    let (joint, point, a1, a2) = match link {
        Link::Ball { point } => (Joint::NoTwist, point, Vector3::x(), Vector3::y()),
        Link::Hinges {
            p1,
            a1,
            p2,
            a2,
            second,
        } => {
            let (a1, a2) = (a1.normalize(), a2.normalize());
            let n = a1.cross(&a2);
            if n.norm() < 1e-9 {
                return Err(second.error(
                    file,
                    "the two hinge axes are parallel: a universal joint needs two crossing axes",
                ));
            }
            // closest points of the two axes: p1 + t a1 = p2 + u a2 (+ gap along n)
            let w = p2 - p1;
            let gap = w.dot(&n) / n.norm();
            let scale = 1.0 + p1.norm().max(p2.norm());
            if gap.abs() > 1e-9 * scale {
                return Err(second.error(
                    file,
                    format!(
                        "the two hinge axes do not meet (they pass {:.3e} m apart): catflip's universal joint turns about one point",
                        gap.abs()
                    ),
                ));
            }
            let (b, c, d, e) = (
                a1.dot(&a2),
                a1.dot(&w),
                a2.dot(&w),
                1.0 - a1.dot(&a2).powi(2),
            );
            let t = (c - b * d) / e;
            (Joint::Universal, p1 + a1 * t, a1, a2)
        }
    };
    let rigid = |p: &Part, axis: Vector3<f64>| Rigid {
        mass: p.mass,
        com: p.com.into(),
        inertia: std::array::from_fn(|r| std::array::from_fn(|c| p.inertia[(r, c)])),
        joint: point.into(),
        axis: axis.into(),
    };
    let halves = Halves {
        rear: rigid(&rear.0, a1),
        front: rigid(&front.0, a2),
    };
    for (r, (_, site)) in [(&halves.rear, &rear), (&halves.front, &front)] {
        if let Some(p) = r.problem() {
            return Err(site.error(file, p));
        }
    }
    Ok((halves, joint))
}
