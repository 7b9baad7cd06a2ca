//! What URDF and MJCF share: numbers in attributes, rotations, sites.

use super::Site;
use crate::error::{Error, Result};
use nalgebra::{Matrix3, Rotation3, Unit, UnitQuaternion, Vector3};
use roxmltree::{Document, Node};

pub fn parse<'a>(text: &'a str, file: &str) -> Result<Document<'a>> {
    Document::parse(text).map_err(|e| Error::Import {
        file: file.into(),
        line: e.pos().row as usize,
        element: "the document".into(),
        message: format!("not well-formed XML: {e}"),
    })
}

/// `<tag name="...">` and its line.
pub fn site(node: &Node) -> Site {
    let tag = node.tag_name().name();
    let element = match node.attribute("name") {
        Some(n) => format!("<{tag} name=\"{n}\">"),
        None => format!("<{tag}>"),
    };
    Site {
        element,
        line: node.document().text_pos_at(node.range().start).row as usize,
    }
}

/// The `n` numbers of attribute `attr`, or `default` when it is missing.
pub fn numbers(
    node: &Node,
    attr: &str,
    n: usize,
    default: Option<&[f64]>,
    file: &str,
) -> Result<Vec<f64>> {
    let count = if n == 1 {
        "a number".to_string()
    } else {
        format!("{n} numbers")
    };
    let Some(raw) = node.attribute(attr) else {
        return default.map(|d| d.to_vec()).ok_or_else(|| {
            site(node).error(file, format!("needs the attribute `{attr}` ({count})"))
        });
    };
    let v: std::result::Result<Vec<f64>, _> =
        raw.split_whitespace().map(str::parse::<f64>).collect();
    match v {
        Ok(v) if v.len() == n && v.iter().all(|x| x.is_finite()) => Ok(v),
        _ => Err(site(node).error(
            file,
            format!("attribute `{attr}` = \"{raw}\" must be {count}, finite"),
        )),
    }
}

/// [`numbers`] that give a direction (an axis, a quaternion): not all zero.
pub fn direction(
    node: &Node,
    attr: &str,
    n: usize,
    default: Option<&[f64]>,
    file: &str,
) -> Result<Vec<f64>> {
    let v = numbers(node, attr, n, default, file)?;
    if v.iter().all(|x| *x == 0.0) {
        return Err(site(node).error(
            file,
            format!("attribute `{attr}` is all zeros: it must give a direction (a unit vector or quaternion; the tools normalise others)"),
        ));
    }
    Ok(v)
}

/// A mass attribute, kg: not negative.
pub fn mass(node: &Node, attr: &str, file: &str) -> Result<f64> {
    let m = number(node, attr, None, file)?;
    if m < 0.0 {
        return Err(site(node).error(
            file,
            format!("{attr} = {m} kg is negative: give the body's mass in kg"),
        ));
    }
    Ok(m)
}

pub fn number(node: &Node, attr: &str, default: Option<f64>, file: &str) -> Result<f64> {
    numbers(
        node,
        attr,
        1,
        default.as_ref().map(std::slice::from_ref),
        file,
    )
    .map(|v| v[0])
}

pub fn vec3(v: &[f64]) -> Vector3<f64> {
    Vector3::new(v[0], v[1], v[2])
}

/// URDF's roll-pitch-yaw: `Rz(yaw) Ry(pitch) Rx(roll)`.
pub fn rpy(v: &[f64]) -> Matrix3<f64> {
    *Rotation3::from_euler_angles(v[0], v[1], v[2]).matrix()
}

/// MJCF's `w x y z` quaternion (normalised, as MuJoCo does).
pub fn quat(v: &[f64]) -> Matrix3<f64> {
    let q = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(v[0], v[1], v[2], v[3]));
    *q.to_rotation_matrix().matrix()
}

/// Rotation by `angle` about `axis`.
pub fn axis_angle(axis: &[f64], angle: f64) -> Matrix3<f64> {
    *Rotation3::from_axis_angle(&Unit::new_normalize(vec3(axis)), angle).matrix()
}

/// A symmetric tensor from its six moments.
pub fn tensor(xx: f64, yy: f64, zz: f64, xy: f64, xz: f64, yz: f64) -> Matrix3<f64> {
    Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz)
}
