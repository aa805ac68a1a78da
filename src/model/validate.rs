//! The checks of a scene, run before anything is built from it: sizes, ranges, names,
//! polygons, points inside their blocks, duplicate and overlapping pairs, roles.
//!
//! A problem is an [`Issue`]: which field (`block 'roof' material.density`), what is wrong
//! and what would be accepted, and where it is in the scene's table structure, so that a
//! scene read from a file reports `file:line`.

use std::collections::{HashMap, HashSet};

use super::geometry::{self, Point};
use super::scene::{ArcDef, ExcitationDef, GroundKind, Scene};
use crate::limits::{
    FREQUENCY_RANGE_HZ, MAX_ACCEL_G, MAX_BLOCKS, MAX_COORDINATE_M, MAX_ELEMENTS, MAX_FORCE_N,
    MAX_GRAVITY, MAX_POLYGON_VERTICES, MAX_SCENE_VERTICES, MAX_SPAN_RATIO, MIN_AMPLITUDE_G,
    STIFFNESS_RANGE,
};
use crate::{Error, Result};

/// Where an issue is in the scene's TOML structure.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum At {
    /// A top-level key (`gravity`, `name`).
    Key(&'static str),
    /// A key of a table (`[ground]`, `[structure]`…), or the table itself.
    Table(&'static str, Option<&'static str>),
    /// A key of the n-th (0-based) entry of an array of tables (`[[block]]`…).
    Item(&'static str, usize, Option<&'static str>),
}

/// One problem of a scene.
#[derive(Debug, Clone, PartialEq)]
pub struct Issue {
    /// Where it is.
    pub at: At,
    /// The field, as a user would name it (`block 'roof' material.density`).
    pub field: String,
    /// What is wrong and what would be accepted.
    pub message: String,
}

impl Issue {
    fn new(at: At, field: impl Into<String>, message: impl Into<String>) -> Self {
        Self {
            at,
            field: field.into(),
            message: message.into(),
        }
    }

    /// An issue from a library error about this field.
    fn from_error(at: At, field: impl Into<String>, e: Error) -> Self {
        match e {
            Error::InvalidParameter { field, message } => Self::new(at, field, message),
            Error::Scene(message) => Self::new(at, field, message),
            other => Self::new(at, field, other.to_string()),
        }
    }

    /// The error, located in the scene's text when there is one.
    pub fn into_error(self, file: Option<(&str, &str)>) -> Error {
        let what = if self.field.is_empty() {
            self.message
        } else {
            format!("{}: {}", self.field, self.message)
        };
        match file {
            Some((label, text)) => match locate(text, self.at) {
                0 => Error::Scene(format!("{label}: {what}")),
                line => Error::Scene(format!("{label}:{line}: {what}")),
            },
            None => Error::Scene(what),
        }
    }
}

type Check = std::result::Result<(), Issue>;

/// The 1-based line of `at` in a scene's TOML text, 0 if it cannot be found (an inline
/// table, a key left at its default).
pub fn locate(text: &str, at: At) -> usize {
    let header = |line: &str| -> Option<(bool, String)> {
        let t = line.trim();
        if let Some(rest) = t.strip_prefix("[[") {
            return Some((true, rest.split("]]").next()?.trim().to_string()));
        }
        let rest = t.strip_prefix('[')?;
        Some((false, rest.split(']').next()?.trim().to_string()))
    };
    let is_key = |line: &str, key: &str| {
        line.trim()
            .strip_prefix(key)
            .is_some_and(|r| r.trim_start().starts_with('='))
    };
    let lines: Vec<&str> = text.lines().collect();
    // The first line of the wanted table, then the key inside it.
    let (start, key) = match at {
        At::Key(key) => (0, Some(key)),
        At::Table(name, key) => {
            let Some(k) = lines
                .iter()
                .position(|l| header(l) == Some((false, name.to_string())))
            else {
                return 0;
            };
            (k, key)
        }
        At::Item(name, index, key) => {
            let Some(k) = lines
                .iter()
                .enumerate()
                .filter(|(_, l)| header(l) == Some((true, name.to_string())))
                .map(|(k, _)| k)
                .nth(index)
            else {
                return 0;
            };
            (k, key)
        }
    };
    let Some(key) = key else {
        return start + 1;
    };
    let body_start = if matches!(at, At::Key(_)) {
        0
    } else {
        start + 1
    };
    for (k, line) in lines.iter().enumerate().skip(body_start) {
        if header(line).is_some() {
            break;
        }
        if is_key(line, key) {
            return k + 1;
        }
    }
    if matches!(at, At::Key(_)) {
        0
    } else {
        start + 1
    }
}

/// Checks a scene; the first problem found.
pub fn check(scene: &Scene) -> Check {
    check_sizes(scene)?;
    check_top(scene)?;
    let names = check_blocks(scene)?;
    let ground = *names.get(scene.ground.block.as_str()).ok_or_else(|| {
        Issue::new(
            At::Table("ground", Some("block")),
            "ground.block",
            format!(
                "no block named '{}' (blocks: {})",
                scene.ground.block,
                block_list(scene)
            ),
        )
    })?;
    check_ground(scene)?;
    check_contacts(scene, &names)?;
    check_bolts(scene, &names)?;
    check_connections(scene, &names)?;
    check_supports(scene, &names, ground)?;
    check_excitation(scene)?;
    check_span(scene, ground)?;
    check_overlaps(scene)?;
    check_one_role_section(scene)?;
    check_structure_roles(scene, &names, ground)?;
    check_sliding_block_roles(scene, &names, ground)?;
    check_two_block_roles(scene, &names, ground)
}

/// A scene is a two-block model, a building or a sliding block: at most one of the role
/// sections, since each makes runs measure different blocks.
fn check_one_role_section(scene: &Scene) -> Check {
    let given: Vec<&str> = [
        ("two_block", scene.two_block.is_some()),
        ("structure", scene.structure.is_some()),
        ("sliding_block", scene.sliding_block.is_some()),
    ]
    .into_iter()
    .filter_map(|(name, given)| given.then_some(name))
    .collect();
    if given.len() > 1 {
        return Err(Issue::new(
            At::Table(
                if scene.sliding_block.is_some() {
                    "sliding_block"
                } else {
                    "structure"
                },
                None,
            ),
            given.join(", "),
            format!(
                "the scene declares [{}]: give one of [two_block], [structure] and \
                 [sliding_block], the roles its runs measure",
                given.join("] and [")
            ),
        ));
    }
    Ok(())
}

fn check_sliding_block_roles(scene: &Scene, names: &HashMap<&str, usize>, ground: usize) -> Check {
    let Some(r) = &scene.sliding_block else {
        return Ok(());
    };
    let at = |key| At::Table("sliding_block", Some(key));
    let block = block_of(names, &r.block, at("block"), "sliding_block.block")?;
    if block == ground {
        return Err(Issue::new(
            at("block"),
            "sliding_block.block",
            format!(
                "'{}' is the ground; name the block that slides on it",
                r.block
            ),
        ));
    }
    if let Some(radius) = r.dish_radius {
        let (lo, hi) = super::pendulum::RADIUS_RANGE_M;
        if !(lo..=hi).contains(&radius) {
            return Err(Issue::new(
                at("dish_radius"),
                "sliding_block.dish_radius",
                format!("the effective radius must be in [{lo}, {hi}] m, got {radius}"),
            ));
        }
    }
    check_joint(
        scene,
        &r.joint,
        [&r.block, &scene.ground.block],
        at("joint"),
        "sliding_block.joint",
    )
}

fn block_list(scene: &Scene) -> String {
    let names: Vec<&str> = scene
        .blocks
        .iter()
        .map(|b| b.name.as_str())
        .take(20)
        .collect();
    let more = if scene.blocks.len() > 20 { ", …" } else { "" };
    format!("{}{more}", names.join(", "))
}

fn check_sizes(scene: &Scene) -> Check {
    if scene.blocks.len() > MAX_BLOCKS {
        return Err(Issue::new(
            At::Item("block", MAX_BLOCKS, None),
            "block",
            format!(
                "{} blocks; a scene may have at most {MAX_BLOCKS}",
                scene.blocks.len()
            ),
        ));
    }
    let vertices: usize = scene.blocks.iter().map(|b| b.vertices.len()).sum();
    if vertices > MAX_SCENE_VERTICES {
        return Err(Issue::new(
            At::Key("name"),
            "block vertices",
            format!("{vertices} vertices in all; a scene may have at most {MAX_SCENE_VERTICES}"),
        ));
    }
    for (table, count) in [
        ("contact", scene.contacts.len()),
        ("bolt", scene.bolts.len()),
        ("connection", scene.connections.len()),
        ("fixed_point", scene.fixed_points.len()),
        ("point_load", scene.point_loads.len()),
    ] {
        if count > MAX_ELEMENTS {
            return Err(Issue::new(
                At::Item(table, MAX_ELEMENTS, None),
                table,
                format!("{count} entries; at most {MAX_ELEMENTS}"),
            ));
        }
    }
    Ok(())
}

fn check_top(scene: &Scene) -> Check {
    if scene.name.trim().is_empty() {
        return Err(Issue::new(At::Key("name"), "name", "must not be empty"));
    }
    let g = scene.gravity;
    if !(g.is_finite() && (0.0..=MAX_GRAVITY).contains(&g)) {
        return Err(Issue::new(
            At::Key("gravity"),
            "gravity",
            format!(
                "must be in [0, {MAX_GRAVITY}] m/s², got {}",
                crate::error::show(g)
            ),
        ));
    }
    if g == 0.0 && scene.contacts.iter().any(|c| !c.bonded) {
        return Err(Issue::new(
            At::Key("gravity"),
            "gravity",
            "is 0 but the scene has frictional contacts: without weight a joint carries no \
             normal force, so it has no friction and the open-close iteration cannot decide \
             its state; give gravity > 0 (9.80665 on Earth) or bond the contacts",
        ));
    }
    Ok(())
}

/// Checks a point's coordinates.
fn check_point(at: At, field: &str, p: Point) -> Check {
    if !(p[0].is_finite() && p[1].is_finite())
        || p[0].abs() > MAX_COORDINATE_M
        || p[1].abs() > MAX_COORDINATE_M
    {
        return Err(Issue::new(
            at,
            field,
            format!(
                "point ({}, {}) must have finite coordinates within ±{MAX_COORDINATE_M:e} m",
                crate::error::show(p[0]),
                crate::error::show(p[1])
            ),
        ));
    }
    Ok(())
}

/// Block names → indices; every block's polygon and material checked.
fn check_blocks(scene: &Scene) -> std::result::Result<HashMap<&str, usize>, Issue> {
    if scene.blocks.len() < 2 {
        return Err(Issue::new(
            At::Key("name"),
            "block",
            "a scene needs the ground and at least one block",
        ));
    }
    let mut names = HashMap::new();
    for (i, b) in scene.blocks.iter().enumerate() {
        let at = |key| At::Item("block", i, Some(key));
        if b.name.trim().is_empty() {
            return Err(Issue::new(
                at("name"),
                format!("block {}", i + 1),
                "the name must not be empty (contacts, bolts and roles refer to blocks by name)",
            ));
        }
        if names.insert(b.name.as_str(), i).is_some() {
            return Err(Issue::new(
                at("name"),
                format!("block '{}'", b.name),
                "two blocks have this name",
            ));
        }
        let field = format!("block '{}' vertices", b.name);
        let n = b.vertices.len();
        if !(3..=MAX_POLYGON_VERTICES).contains(&n) {
            return Err(Issue::new(
                at("vertices"),
                field,
                format!("a polygon has 3 to {MAX_POLYGON_VERTICES} vertices, got {n}"),
            ));
        }
        for &p in &b.vertices {
            check_point(at("vertices"), &field, p)?;
        }
        geometry::moments(&b.vertices, &b.name)
            .and_then(|_| geometry::check_simple(&b.vertices, &b.name))
            .map_err(|e| Issue::from_error(at("vertices"), "", e))?;
        for (k, arc) in b.arcs.iter().enumerate() {
            let field = format!("block '{}' arc {}", b.name, k + 1);
            check_arc(&b.vertices, arc).map_err(|why| Issue::new(at("arcs"), field, why))?;
        }
        if let Some(edge) = (0..n).find(|&e| b.arcs.iter().filter(|a| a.holds_edge(e)).count() > 1)
        {
            return Err(Issue::new(
                at("arcs"),
                format!("block '{}' arcs", b.name),
                format!("edge {edge} is in two arcs; a chord belongs to one circle"),
            ));
        }
        b.material
            .validate(&format!("block '{}' material", b.name))
            .map_err(|e| Issue::from_error(at("material"), "", e))?;
    }
    Ok(names)
}

/// An arc's edges must exist, their vertices lie on its circle, and the circle's centre be
/// on their free side (a dish: the contact law of a convex arc is not written).
fn check_arc(vertices: &[Point], arc: &ArcDef) -> std::result::Result<(), String> {
    let n = vertices.len();
    let [first, last] = arc.edges;
    let finite = arc.center.iter().all(|c| c.is_finite());
    if !(finite && arc.radius.is_finite() && arc.radius > 0.0) {
        return Err(format!(
            "needs a finite centre and a positive radius, got centre ({}, {}), radius {}",
            arc.center[0], arc.center[1], arc.radius
        ));
    }
    if first > last || last >= n {
        return Err(format!(
            "edges [{first}, {last}] are not a run of this polygon's edges 0 to {}",
            n - 1
        ));
    }
    let tolerance = 1e-6 * arc.radius;
    for k in first..=last + 1 {
        let p = vertices[k % n];
        let off = geometry::sub(p, arc.center);
        let off = off[0].hypot(off[1]) - arc.radius;
        if off.abs() > tolerance {
            return Err(format!(
                "vertex {} ({}, {}) is {off:.3e} m off the circle of radius {} about ({}, {}); \
                 an arc's edges must be chords of its circle (to 1e-6 of the radius)",
                k % n,
                p[0],
                p[1],
                arc.radius,
                arc.center[0],
                arc.center[1]
            ));
        }
    }
    for k in first..=last {
        let (a, b) = (vertices[k], vertices[(k + 1) % n]);
        let edge = geometry::sub(b, a);
        let to_centre = geometry::sub(arc.center, a);
        // Counter-clockwise polygon: the outside is to the right of an edge.
        if geometry::cross(edge, to_centre) >= 0.0 {
            return Err(format!(
                "the circle's centre is inside the block from edge {k}: an arc must be a \
                 dish (its centre on the free side of every chord)"
            ));
        }
    }
    Ok(())
}

fn check_ground(scene: &Scene) -> Check {
    if scene.ground.kind == GroundKind::LargeMass {
        crate::error::require_range("ground.mass_ratio", scene.ground.mass_ratio, 1.0, 1e8, "")
            .map_err(|e| Issue::from_error(At::Table("ground", Some("mass_ratio")), "", e))?;
    }
    Ok(())
}

/// The index of a named block, or an issue naming the field.
fn block_of(
    names: &HashMap<&str, usize>,
    name: &str,
    at: At,
    field: &str,
) -> std::result::Result<usize, Issue> {
    names
        .get(name)
        .copied()
        .ok_or_else(|| Issue::new(at, field, format!("no block named '{name}'")))
}

fn check_stiffness(at: At, field: &str, value: f64) -> Check {
    let (lo, hi) = STIFFNESS_RANGE;
    crate::error::require_range(field, value, lo, hi, "N/m")
        .map(|_| ())
        .map_err(|e| Issue::from_error(at, "", e))
}

/// How the k-th entry of a table is named in messages (`contact 'joint'`, or `contact 3`
/// when it has no name); a name used twice in the table is an issue (roles find entries
/// by name).
fn named<'a>(
    kind: &str,
    k: usize,
    name: &'a str,
    seen: &mut HashSet<&'a str>,
    at: At,
) -> std::result::Result<String, Issue> {
    if name.is_empty() {
        return Ok(format!("{kind} {}", k + 1));
    }
    let label = format!("{kind} '{name}'");
    if !seen.insert(name) {
        return Err(Issue::new(at, label, format!("two {kind}s have this name")));
    }
    Ok(label)
}

fn check_contacts(scene: &Scene, names: &HashMap<&str, usize>) -> Check {
    let mut pairs = HashMap::new();
    let mut contact_names = HashSet::new();
    for (k, c) in scene.contacts.iter().enumerate() {
        let at = |key| At::Item("contact", k, Some(key));
        let label = named("contact", k, &c.name, &mut contact_names, at("name"))?;
        let a = block_of(
            names,
            &c.blocks[0],
            at("blocks"),
            &format!("{label} blocks"),
        )?;
        let b = block_of(
            names,
            &c.blocks[1],
            at("blocks"),
            &format!("{label} blocks"),
        )?;
        if a == b {
            return Err(Issue::new(
                at("blocks"),
                format!("{label} blocks"),
                format!("joins block '{}' to itself", c.blocks[0]),
            ));
        }
        if let Some(first) = pairs.insert((a.min(b), a.max(b)), k) {
            return Err(Issue::new(
                at("blocks"),
                format!("{label} blocks"),
                format!(
                    "blocks '{}' and '{}' are already a contact pair (contact {}); a pair \
                     declared twice would act with double springs",
                    c.blocks[0],
                    c.blocks[1],
                    first + 1
                ),
            ));
        }
        if let Err(problem) = c.friction.check() {
            return Err(Issue::new(
                at("friction"),
                format!("{label} friction"),
                problem,
            ));
        }
        for (key, v) in [
            ("normal_penalty", c.normal_penalty),
            ("shear_penalty", c.shear_penalty),
        ] {
            if let Some(v) = v {
                check_stiffness(at(key), &format!("{label} {key}"), v)?;
            }
        }
    }
    Ok(())
}

/// Checks that `p` lies in block `b` (within a thousandth of the block's size).
fn check_inside(scene: &Scene, b: usize, p: Point, at: At, field: &str) -> Check {
    check_point(at, field, p)?;
    let block = &scene.blocks[b];
    let tol = 1e-3 * geometry::bounding_size(&block.vertices);
    let outside = geometry::distance_outside(&block.vertices, p);
    if outside > tol {
        return Err(Issue::new(
            at,
            field,
            format!(
                "point ({}, {}) lies {outside:.4e} m outside block '{}'; a point must be in \
                 (or on the edge of) the block that carries it",
                p[0], p[1], block.name
            ),
        ));
    }
    Ok(())
}

fn check_bolts(scene: &Scene, names: &HashMap<&str, usize>) -> Check {
    let mut bolt_names = HashSet::new();
    for (k, bolt) in scene.bolts.iter().enumerate() {
        let at = |key| At::Item("bolt", k, Some(key));
        let label = named("bolt", k, &bolt.name, &mut bolt_names, at("name"))?;
        let field = format!("{label} blocks");
        let a = block_of(names, &bolt.blocks[0], at("blocks"), &field)?;
        let b = block_of(names, &bolt.blocks[1], at("blocks"), &field)?;
        if a == b {
            return Err(Issue::new(at("blocks"), field, "joins a block to itself"));
        }
        for (end, block) in [(0, a), (1, b)] {
            check_inside(
                scene,
                block,
                bolt.points[end],
                at("points"),
                &format!("{label} points[{end}]"),
            )?;
        }
        check_stiffness(
            at("stiffness"),
            &format!("{label} stiffness"),
            bolt.stiffness,
        )?;
        crate::error::require_range(
            &format!("{label} damping"),
            bolt.damping,
            0.0,
            1e15,
            "N·s/m",
        )
        .map_err(|e| Issue::from_error(at("damping"), "", e))?;
    }
    Ok(())
}

fn check_connections(scene: &Scene, names: &HashMap<&str, usize>) -> Check {
    for (k, c) in scene.connections.iter().enumerate() {
        let at = |key| At::Item("connection", k, Some(key));
        let label = format!("connection {}", k + 1);
        let mut owners = [0; 3];
        for (n, node) in c.nodes.iter().enumerate() {
            let field = format!("{label} node {}", n + 1);
            owners[n] = block_of(names, &node.block, at("nodes"), &field)?;
            check_inside(scene, owners[n], node.point, at("nodes"), &field)?;
        }
        if owners[0] == owners[1] && owners[1] == owners[2] {
            return Err(Issue::new(
                at("nodes"),
                label,
                format!(
                    "all three nodes are in block '{}'; a connection joins 2 or 3 blocks",
                    c.nodes[0].block
                ),
            ));
        }
        let pts: Vec<Point> = c.nodes.iter().map(|n| n.point).collect();
        geometry::moments(&pts, &label).map_err(|e| Issue::from_error(at("nodes"), "", e))?;
        c.material
            .validate(&format!("{label} material"))
            .map_err(|e| Issue::from_error(at("material"), "", e))?;
    }
    Ok(())
}

fn check_supports(scene: &Scene, names: &HashMap<&str, usize>, ground: usize) -> Check {
    for (k, f) in scene.fixed_points.iter().enumerate() {
        let at = |key| At::Item("fixed_point", k, Some(key));
        let label = format!("fixed_point {}", k + 1);
        let b = block_of(names, &f.block, at("block"), &format!("{label} block"))?;
        check_inside(scene, b, f.point, at("point"), &format!("{label} point"))?;
        if let Some(p) = f.penalty {
            check_stiffness(at("penalty"), &format!("{label} penalty"), p)?;
        }
    }
    for (k, l) in scene.point_loads.iter().enumerate() {
        let at = |key| At::Item("point_load", k, Some(key));
        let label = format!("point_load {}", k + 1);
        let b = block_of(names, &l.block, at("block"), &format!("{label} block"))?;
        if b == ground && scene.ground.kind == GroundKind::Prescribed {
            return Err(Issue::new(
                at("block"),
                format!("{label} block"),
                "a point load on a prescribed ground has no effect",
            ));
        }
        check_inside(scene, b, l.point, at("point"), &format!("{label} point"))?;
        let f = l.force;
        if !(f[0].is_finite() && f[1].is_finite() && f[0].hypot(f[1]) <= MAX_FORCE_N) {
            return Err(Issue::new(
                at("force"),
                format!("{label} force"),
                format!(
                    "({}, {}) must be finite, at most {MAX_FORCE_N:e} N",
                    f[0], f[1]
                ),
            ));
        }
    }
    Ok(())
}

fn check_excitation(scene: &Scene) -> Check {
    if let Some(v) = &scene.vertical_excitation {
        let at = |key| At::Table("vertical_excitation", Some(key));
        if v.record.trim().is_empty() {
            return Err(Issue::new(
                at("record"),
                "vertical_excitation.record",
                "must name a built-in vertical record (el-centro-up) or a file",
            ));
        }
        crate::error::require_range("vertical_excitation.scale", v.scale, 1e-6, 1e3, "")
            .map_err(|e| Issue::from_error(at("scale"), "", e))?;
    }
    let at = |key| At::Table("excitation", Some(key));
    match &scene.excitation {
        ExcitationDef::None => Ok(()),
        ExcitationDef::Harmonic {
            amplitude_g,
            frequency_hz,
        } => {
            crate::error::require_range(
                "excitation.amplitude_g",
                *amplitude_g,
                MIN_AMPLITUDE_G,
                MAX_ACCEL_G,
                "g",
            )
            .map_err(|e| Issue::from_error(at("amplitude_g"), "", e))?;
            let (lo, hi) = FREQUENCY_RANGE_HZ;
            crate::error::require_range("excitation.frequency_hz", *frequency_hz, lo, hi, "Hz")
                .map_err(|e| Issue::from_error(at("frequency_hz"), "", e))?;
            Ok(())
        }
        ExcitationDef::Record { record, scale } => {
            if record.trim().is_empty() {
                return Err(Issue::new(
                    at("record"),
                    "excitation.record",
                    "must name a built-in record or a file",
                ));
            }
            crate::error::require_range("excitation.scale", *scale, 1e-6, 1e3, "")
                .map_err(|e| Issue::from_error(at("scale"), "", e))?;
            Ok(())
        }
    }
}

/// The structure (every block but the ground) must not span far more than its smallest
/// block (see [`MAX_SPAN_RATIO`]).
fn check_span(scene: &Scene, ground: usize) -> Check {
    let structure: Vec<(usize, f64)> = scene
        .blocks
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != ground)
        .map(|(i, b)| (i, geometry::bounding_size(&b.vertices)))
        .collect();
    let span = scene.structure_size();
    let Some(&(smallest, size)) = structure.iter().min_by(|a, b| a.1.total_cmp(&b.1)) else {
        return Ok(());
    };
    if span > MAX_SPAN_RATIO * size {
        return Err(Issue::new(
            At::Item("block", smallest, Some("vertices")),
            "block",
            format!(
                "the structure spans {span:.4e} m but block '{}' is {size:.4e} m across: \
                 more than {MAX_SPAN_RATIO:e} times its smallest block, the solver's \
                 contact tolerances (fractions of the structure's size) would swallow that \
                 block's contacts; run far-apart structures as separate scenes",
                scene.blocks[smallest].name
            ),
        ));
    }
    Ok(())
}

/// Blocks that overlap must be a declared contact pair, and even then only by a rounding
/// error (see [`check_declared_overlap`]); two undeclared blocks would pass through each
/// other unseen.
fn check_overlaps(scene: &Scene) -> Check {
    let declared: HashSet<(&str, &str)> = scene
        .contacts
        .iter()
        .flat_map(|c| {
            [
                (c.blocks[0].as_str(), c.blocks[1].as_str()),
                (c.blocks[1].as_str(), c.blocks[0].as_str()),
            ]
        })
        .collect();
    let boxes: Vec<([f64; 2], [f64; 2])> = scene
        .blocks
        .iter()
        .map(|b| {
            let mut lo = [f64::INFINITY; 2];
            let mut hi = [f64::NEG_INFINITY; 2];
            for p in &b.vertices {
                for d in 0..2 {
                    lo[d] = lo[d].min(p[d]);
                    hi[d] = hi[d].max(p[d]);
                }
            }
            (lo, hi)
        })
        .collect();
    // Sweep along x: only blocks whose x-ranges meet are compared.
    let mut order: Vec<usize> = (0..scene.blocks.len()).collect();
    order.sort_by(|&a, &b| boxes[a].0[0].total_cmp(&boxes[b].0[0]));
    for (k, &a) in order.iter().enumerate() {
        for &b in &order[k + 1..] {
            if boxes[b].0[0] >= boxes[a].1[0] {
                break;
            }
            if boxes[b].0[1] >= boxes[a].1[1] || boxes[a].0[1] >= boxes[b].1[1] {
                continue;
            }
            let (ba, bb) = (&scene.blocks[a], &scene.blocks[b]);
            let depth = overlap_depth(&ba.vertices, &bb.vertices);
            if declared.contains(&(ba.name.as_str(), bb.name.as_str())) {
                check_declared_overlap(scene, [a, b], depth)?;
                continue;
            }
            if let Some(depth) = depth {
                let (first, second) = (a.min(b), a.max(b));
                return Err(Issue::new(
                    At::Item("block", second, Some("vertices")),
                    format!("block '{}'", scene.blocks[second].name),
                    format!(
                        "overlaps block '{}' (by {depth:.4e} m) and the two are not a \
                         declared contact pair; move them apart, or declare a [[contact]] \
                         between them",
                        scene.blocks[first].name
                    ),
                ));
            }
        }
    }
    Ok(())
}

/// A declared contact pair that overlaps at the start by more than the solver's tolerance
/// (a millionth of the structure's span): refused here with the depth, as the solver
/// refuses a shallow one. A vertex sunk deeper than the contact detection's reach was
/// not seen there, and the block "fell" through: reported as an unsupported block.
fn check_declared_overlap(scene: &Scene, pair: [usize; 2], depth: Option<f64>) -> Check {
    let Some(depth) = depth else {
        return Ok(());
    };
    let names = pair.map(|i| scene.blocks[i].name.as_str());
    let bonded = scene.contacts.iter().any(|c| {
        c.bonded && (c.blocks == [names[0], names[1]] || c.blocks == [names[1], names[0]])
    });
    if bonded || depth <= 1e-6 * scene.structure_size() {
        return Ok(());
    }
    let second = pair[0].max(pair[1]);
    Err(Issue::new(
        At::Item("block", second, Some("vertices")),
        format!("block '{}'", scene.blocks[second].name),
        format!(
            "overlaps block '{}' by {depth:.4e} m at the start; blocks in contact must only \
             touch: move them apart",
            scene.blocks[pair[0].min(pair[1])].name
        ),
    ))
}

/// How deep two polygons overlap, if they do by more than a millionth of the smaller one:
/// a vertex, edge midpoint or centroid of one inside the other (the midpoints and centroids
/// catch overlaps whose vertices all lie on the other's edges), or edges that cross.
fn overlap_depth(a: &[Point], b: &[Point]) -> Option<f64> {
    let tol = 1e-6 * geometry::bounding_size(a).min(geometry::bounding_size(b));
    let probes = |poly: &[Point]| -> Vec<Point> {
        let n = poly.len();
        let mut pts: Vec<Point> = poly.to_vec();
        pts.extend((0..n).map(|k| {
            let (p, q) = (poly[k], poly[(k + 1) % n]);
            [0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])]
        }));
        if let Ok(m) = geometry::moments(poly, "") {
            pts.push(m.centroid);
        }
        pts
    };
    let inside = |poly: &[Point], p: Point| {
        geometry::contains(poly, p)
            .then(|| geometry::boundary_distance(poly, p))
            .filter(|&d| d > tol)
    };
    let deepest = probes(a)
        .into_iter()
        .filter_map(|p| inside(b, p))
        .chain(probes(b).into_iter().filter_map(|p| inside(a, p)))
        .fold(None, |m: Option<f64>, d| Some(m.map_or(d, |m| m.max(d))));
    if deepest.is_some() {
        return deepest;
    }
    let (na, nb) = (a.len(), b.len());
    for i in 0..na {
        for j in 0..nb {
            if geometry::segments_cross(a[i], a[(i + 1) % na], b[j], b[(j + 1) % nb], tol) {
                return Some(tol);
            }
        }
    }
    None
}

/// The contact of this name must join exactly these two blocks.
fn check_joint(scene: &Scene, joint: &str, blocks: [&str; 2], at: At, field: &str) -> Check {
    let Some(c) = scene.contacts.iter().find(|c| c.name == joint) else {
        return Err(Issue::new(at, field, format!("no contact named '{joint}'")));
    };
    let joins = |x: &str, y: &str| c.blocks[0] == x && c.blocks[1] == y;
    if !(joins(blocks[0], blocks[1]) || joins(blocks[1], blocks[0])) {
        return Err(Issue::new(
            at,
            field,
            format!(
                "contact '{joint}' joins '{}' and '{}', but the sliding joint must join \
                 '{}' and '{}'",
                c.blocks[0], c.blocks[1], blocks[0], blocks[1]
            ),
        ));
    }
    Ok(())
}

fn check_structure_roles(scene: &Scene, names: &HashMap<&str, usize>, ground: usize) -> Check {
    let Some(r) = &scene.structure else {
        return Ok(());
    };
    let at = |key| At::Table("structure", Some(key));
    let base = block_of(names, &r.base, at("base"), "structure.base")?;
    if base == ground {
        return Err(Issue::new(
            at("base"),
            "structure.base",
            format!(
                "'{}' is the ground; the base is the block that slides on the ground",
                r.base
            ),
        ));
    }
    if r.floors.is_empty() {
        return Err(Issue::new(
            at("floors"),
            "structure.floors",
            "must name at least one floor, bottom to top",
        ));
    }
    let height = |b: usize| {
        geometry::moments(&scene.blocks[b].vertices, "").map_or(f64::NAN, |m| m.centroid[1])
    };
    let (mut below, mut below_name) = (height(base), r.base.as_str());
    let mut seen = HashSet::from([base, ground]);
    for f in &r.floors {
        let b = block_of(names, f, at("floors"), "structure.floors")?;
        if !seen.insert(b) {
            return Err(Issue::new(
                at("floors"),
                "structure.floors",
                format!("'{f}' is the ground, the base or a floor named twice"),
            ));
        }
        let h = height(b);
        if h.partial_cmp(&below) != Some(std::cmp::Ordering::Greater) {
            return Err(Issue::new(
                at("floors"),
                "structure.floors",
                format!(
                    "floors are listed bottom to top, but '{f}' (centroid at y = {h:.4} m) \
                     is not above '{below_name}' (y = {below:.4} m)"
                ),
            ));
        }
        (below, below_name) = (h, f.as_str());
    }
    check_joint(
        scene,
        &r.joint,
        [&r.base, &scene.ground.block],
        at("joint"),
        "structure.joint",
    )
}

fn check_two_block_roles(scene: &Scene, names: &HashMap<&str, usize>, ground: usize) -> Check {
    let Some(r) = &scene.two_block else {
        return Ok(());
    };
    let at = |key| At::Table("two_block", Some(key));
    let raft = block_of(names, &r.raft, at("raft"), "two_block.raft")?;
    let roof = block_of(names, &r.roof, at("roof"), "two_block.roof")?;
    for (key, b, name) in [("raft", raft, &r.raft), ("roof", roof, &r.roof)] {
        if b == ground {
            return Err(Issue::new(
                at(key),
                format!("two_block.{key}"),
                format!("'{name}' is the ground"),
            ));
        }
    }
    if raft == roof {
        return Err(Issue::new(
            at("roof"),
            "two_block.roof",
            format!(
                "'{}' is also the raft; the roof is the mass m on the spring",
                r.roof
            ),
        ));
    }
    let Some(spring) = scene.bolts.iter().find(|b| b.name == r.spring) else {
        return Err(Issue::new(
            at("spring"),
            "two_block.spring",
            format!("no bolt named '{}'", r.spring),
        ));
    };
    let ends: HashSet<&str> = spring.blocks.iter().map(String::as_str).collect();
    if ends != HashSet::from([r.raft.as_str(), r.roof.as_str()]) {
        return Err(Issue::new(
            at("spring"),
            "two_block.spring",
            format!(
                "bolt '{}' must join the raft '{}' and the roof '{}'",
                r.spring, r.raft, r.roof
            ),
        ));
    }
    check_joint(
        scene,
        &r.joint,
        [&r.raft, &scene.ground.block],
        at("joint"),
        "two_block.joint",
    )?;
    let (lo, hi) = FREQUENCY_RANGE_HZ;
    crate::error::require_range(
        "two_block.structure_frequency_hz",
        r.structure_frequency_hz,
        lo,
        hi,
        "Hz",
    )
    .map_err(|e| Issue::from_error(at("structure_frequency_hz"), "", e))?;
    crate::error::require_range("two_block.total_mass", r.total_mass, 1e-6, 1e15, "kg")
        .map_err(|e| Issue::from_error(at("total_mass"), "", e))?;
    Ok(())
}

/// Scene methods built on the checks.
impl Scene {
    /// Checks sizes, names, polygons, materials, ranges, points, pairs and roles.
    pub fn validate(&self) -> Result<()> {
        check(self).map_err(|i| i.into_error(None))
    }
}
