//! Scenes generated from a size, for scaling studies and larger demonstrations:
//!
//! - `frame:N` — the paper's frame with N storeys (the three-storey scene's geometry,
//!   materials and connection elements, repeated upwards; `frame:3` is `three-storey`);
//! - `wall:N` — a wall of N courses of N dry-stacked blocks (running bond) on a base slab
//!   that slides on the ground: every block touches its neighbours through frictional
//!   contacts, so the contact search and the open-close iteration grow with the wall.
//!
//! Both are ordinary [`Scene`]s: they can be run, rendered or written out as TOML.

use super::enforcement::ContactEnforcement;
use super::friction::Friction;
use super::material::Material;
use super::scene::{
    BlockDef, ConnectionDef, ConnectionNode, ContactDef, ExcitationDef, GroundDef, GroundKind,
    Scene, StructureRoles,
};
use crate::ground_motion::STANDARD_GRAVITY;
use crate::{Error, Result};

/// Tallest frame that stands: the paper's floors are heavy (they give the three-storey
/// frame its 0.638 Hz) and its columns slender, so the weight above a storey over the
/// storey height (P-Δ) eats the columns' lateral stiffness as floors are added. The first
/// sway frequency falls from 0.634 Hz (3 storeys) to 0.062 Hz (19) and 0.053 Hz (20), and
/// is gone at 21: that frame buckles under its own weight. (21 stood while the connection
/// elements' stress stayed in global axes as they turned; since it turns with them, stop
/// 31, their axial preload acts on the sway too.) `slidebase modes --scene frame:N` shows
/// it.
pub const MAX_FRAME_STOREYS: usize = 20;

/// A generated scene from its spelling `frame:N`, `wall:N` or `friction-pendulum[:R]`
/// (see [`super::pendulum`]), or `None` when the name is
/// not of that form.
pub fn resolve_generated(name: &str) -> Option<Result<Scene>> {
    if let Some(pendulum) = super::pendulum::resolve(name) {
        return Some(pendulum);
    }
    let (kind, size) = name.split_once(':')?;
    let build: fn(usize) -> Result<Scene> = match kind {
        "frame" => frame,
        "wall" => wall,
        _ => return None,
    };
    Some(
        size.parse::<usize>()
            .map_err(|_| {
                Error::invalid(
                    "--scene",
                    format!("'{name}': the size after ':' must be a whole number"),
                )
            })
            .and_then(build),
    )
}

fn check_size(kind: &str, n: usize, max: usize) -> Result<()> {
    if n == 0 || n > max {
        return Err(Error::invalid(
            "--scene",
            format!("{kind}:{n}: the size must be between 1 and {max}"),
        ));
    }
    Ok(())
}

fn rectangle(x0: f64, y0: f64, x1: f64, y1: f64) -> Vec<[f64; 2]> {
    vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]]
}

fn concrete(density: f64) -> Material {
    Material {
        density,
        youngs_modulus: 2.0e10,
        poisson_ratio: 0.15,
        plane: Default::default(),
    }
}

fn node(block: &str, point: [f64; 2]) -> ConnectionNode {
    ConnectionNode {
        block: block.into(),
        point,
    }
}

/// The four constant-strain triangles that join the bottom edge `[x0, x1] × {y_low}` of a
/// gap to its top edge at `y_high`: both diagonal splits, each at half the modulus, so
/// that the connection is symmetric (as in the three-storey scene).
fn connection(
    lower: &str,
    upper: &str,
    x0: f64,
    x1: f64,
    y_low: f64,
    y_high: f64,
) -> Vec<ConnectionDef> {
    let material = Material {
        density: 1.0,
        youngs_modulus: 1.0e10,
        poisson_ratio: 0.15,
        plane: Default::default(),
    };
    let (a0, a1, b0, b1) = ([x0, y_low], [x1, y_low], [x0, y_high], [x1, y_high]);
    [
        [node(lower, a0), node(lower, a1), node(upper, b1)],
        [node(lower, a0), node(upper, b1), node(upper, b0)],
        [node(lower, a0), node(lower, a1), node(upper, b0)],
        [node(lower, a1), node(upper, b1), node(upper, b0)],
    ]
    .into_iter()
    .map(|nodes| ConnectionDef { nodes, material })
    .collect()
}

fn ground_block(half_length: f64) -> BlockDef {
    BlockDef {
        name: "ground".into(),
        vertices: rectangle(-half_length, -1.0, half_length, 0.0),
        material: concrete(2000.0),
        rigid: false,
        arcs: Vec::new(),
    }
}

/// The paper's frame with `storeys` storeys: a base slab on the sliding joint, a slab per
/// floor and two columns per storey, joined by connection elements. Geometry, materials
/// and joint as in `assets/scenes/three-storey.toml` (which `frame:3` reproduces).
pub fn frame(storeys: usize) -> Result<Scene> {
    if storeys > MAX_FRAME_STOREYS {
        return Err(Error::invalid(
            "--scene",
            format!(
                "frame:{storeys}: the paper's frame buckles under its own weight above \
                 {MAX_FRAME_STOREYS} storeys (its heavy floors' weight over the storey height \
                 exceeds the slender columns' lateral stiffness: P-Δ); take frame:1 to \
                 frame:{MAX_FRAME_STOREYS}"
            ),
        ));
    }
    check_size("frame", storeys, MAX_FRAME_STOREYS)?;
    // Slab density that gives the three-storey frame its 0.638 Hz (see that scene);
    // columns carry 1 % of it.
    let slab = concrete(1_789_400.0);
    let column = concrete(17_894.0);
    let (h, t) = (3.0, 0.3);
    let mut blocks = vec![
        ground_block(2000.0),
        BlockDef {
            name: "base-slab".into(),
            vertices: rectangle(-12.3, 0.0, 12.3, t),
            material: slab,
            rigid: false,
            arcs: Vec::new(),
        },
    ];
    let mut connections = Vec::new();
    let mut floors = Vec::new();
    for k in 1..=storeys {
        let below = if k == 1 {
            "base-slab".to_string()
        } else {
            format!("floor-{}", k - 1)
        };
        let y0 = (k - 1) as f64 * h;
        let floor = format!("floor-{k}");
        blocks.push(BlockDef {
            name: floor.clone(),
            vertices: rectangle(-12.3, k as f64 * h, 12.3, k as f64 * h + t),
            material: slab,
            rigid: false,
            arcs: Vec::new(),
        });
        for (side, x0, x1) in [("left", -12.2, -11.8), ("right", 11.8, 12.2)] {
            let name = format!("column-{k}-{side}");
            blocks.push(BlockDef {
                name: name.clone(),
                // (y0 + 0.4 rather than y0 + t + 0.1: the same number as the TOML scene's.)
                vertices: rectangle(x0, y0 + 0.4, x1, k as f64 * h - 0.1),
                material: column,
                rigid: false,
                arcs: Vec::new(),
            });
            connections.extend(connection(&below, &name, x0, x1, y0 + t, y0 + 0.4));
            connections.extend(connection(
                &name,
                &floor,
                x0,
                x1,
                k as f64 * h - 0.1,
                k as f64 * h,
            ));
        }
        floors.push(floor);
    }
    building(
        format!("frame:{storeys}"),
        format!("The paper's frame with {storeys} storeys on a sliding base slab (generated)"),
        blocks,
        vec![ContactDef {
            name: "sliding-joint".into(),
            blocks: ["base-slab".into(), "ground".into()],
            friction: Friction::Coulomb(0.01),
            normal_penalty: Some(2.0e12),
            shear_penalty: Some(2.0e12),
            bonded: false,
            locate_events: true,
        }],
        connections,
        floors,
    )
}

/// A building scene on the ground block `ground`, with a base slab `base-slab` on the
/// contact `sliding-joint`, under El Centro; `floors` name the levels above the base.
fn building(
    name: String,
    description: String,
    blocks: Vec<BlockDef>,
    contacts: Vec<ContactDef>,
    connections: Vec<ConnectionDef>,
    floors: Vec<String>,
) -> Result<Scene> {
    let scene = Scene {
        name,
        description,
        gravity: STANDARD_GRAVITY,
        blocks,
        ground: GroundDef {
            block: "ground".into(),
            kind: GroundKind::Prescribed,
            mass_ratio: 1e4,
        },
        contacts,
        bolts: Vec::new(),
        connections,
        fixed_points: Vec::new(),
        point_loads: Vec::new(),
        excitation: ExcitationDef::Record {
            record: "el-centro".into(),
            scale: 1.0,
        },
        two_block: None,
        sliding_block: None,
        vertical_excitation: None,
        contact_enforcement: None,
        integrator: None,
        structure: Some(StructureRoles {
            base: "base-slab".into(),
            floors,
            joint: "sliding-joint".into(),
        }),
    };
    scene.validate()?;
    Ok(scene)
}

/// Largest wall accepted: 40 courses, about 1620 blocks.
pub const MAX_WALL: usize = 40;

/// A wall of `n` courses of dry-stacked masonry blocks (0.5 m × 0.25 m, friction 0.7
/// between them) in running bond — `n` blocks in the even courses, `n − 1` and two half
/// blocks in the odd ones, with 1 mm head joints — on a base slab that slides on the
/// ground (ρ = 0.1). Every block rests on two below (the bond), and contacts are declared
/// between every pair that touches or could touch: bed joints, head joints (open at the
/// start) and the bottom course on the slab. The top middle block is reported as the
/// "roof".
pub fn wall(n: usize) -> Result<Scene> {
    check_size("wall", n, MAX_WALL)?;
    let (w, h, head) = (0.5, 0.25, 0.001);
    let masonry = Material {
        density: 2000.0,
        youngs_modulus: 5.0e9,
        poisson_ratio: 0.2,
        plane: Default::default(),
    };
    let width = n as f64 * w;
    let mut blocks = vec![
        ground_block(2000.0),
        BlockDef {
            name: "base-slab".into(),
            vertices: rectangle(-0.1, 0.0, width + 0.1, 0.3),
            material: concrete(2400.0),
            rigid: false,
            arcs: Vec::new(),
        },
    ];
    let joint = |a: &str, b: &str| ContactDef {
        name: String::new(),
        blocks: [a.into(), b.into()],
        friction: Friction::Coulomb(0.7),
        normal_penalty: None,
        shear_penalty: None,
        bonded: false,
        // Hundreds of bed and head joints hold blocks at near-zero force and change state
        // in almost every step: their events are taken at step ends (classic DDA), and
        // steps land only on the sliding joint's (twice as fast per step at 1 000 blocks,
        // docs/performance.md).
        locate_events: false,
    };
    let mut contacts = vec![ContactDef {
        name: "sliding-joint".into(),
        blocks: ["base-slab".into(), "ground".into()],
        friction: Friction::Coulomb(0.1),
        normal_penalty: None,
        shear_penalty: None,
        bonded: false,
        locate_events: true,
    }];
    // Each course: (name, x0, x1) of its blocks, left to right.
    let mut below: Vec<(String, f64, f64)> = Vec::new();
    let mut roof = String::new();
    for course in 0..n {
        let y0 = 0.3 + course as f64 * h;
        let mut edges: Vec<f64> = (0..=n).map(|k| k as f64 * w).collect();
        if course % 2 == 1 {
            // Running bond: joints at the middle of the blocks below, half blocks at the ends.
            edges = std::iter::once(0.0)
                .chain((0..n).map(|k| (k as f64 + 0.5) * w))
                .chain(std::iter::once(width))
                .collect();
        }
        let mut this: Vec<(String, f64, f64)> = Vec::new();
        for (k, pair) in edges.windows(2).enumerate() {
            // Head joints: each block is 1 mm short of its neighbour on the right.
            let (x0, x1) = (
                pair[0],
                pair[1] - if k + 2 < edges.len() { head } else { 0.0 },
            );
            let name = format!("block-{course}-{k}");
            blocks.push(BlockDef {
                name: name.clone(),
                vertices: rectangle(x0, y0, x1, y0 + h),
                material: masonry,
                rigid: false,
                arcs: Vec::new(),
            });
            if let Some((left, _, _)) = this.last() {
                contacts.push(joint(left, &name));
            }
            if course == 0 {
                contacts.push(joint(&name, "base-slab"));
            }
            for (other, b0, b1) in &below {
                if *b0 < x1 && x0 < *b1 {
                    contacts.push(joint(other, &name));
                }
            }
            this.push((name, x0, x1));
        }
        if let Some((name, _, _)) = this.get(this.len() / 2) {
            roof = name.clone();
        }
        below = this;
    }
    let mut scene = building(
        format!("wall:{n}"),
        format!(
            "A wall of {n} courses of dry-stacked blocks in running bond on a sliding base slab \
             (generated)"
        ),
        blocks,
        contacts,
        Vec::new(),
        vec![roof],
    )?;
    // Penalty springs for the joints of the dry stack (Shi's DDA): each block rests on
    // two below and touches them at several vertices per face, more constraints (normal
    // and shear at each) than its six freedoms, so the augmented Lagrangian's individual
    // multipliers are not determined; once the wall rocks their iteration stalls
    // (hundreds of iterations per pass, the open-close iteration never settles: `wall:10`
    // on Kobe stopped at 4.5 s), while springs share the load by their stiffness.
    scene.contact_enforcement = Some(ContactEnforcement::Penalty);
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::presets::resolve_scene;

    /// `frame:3` is the built-in three-storey scene, block for block and element for
    /// element (only the name and description differ).
    #[test]
    fn frame_3_is_the_three_storey_scene() {
        let built = resolve_scene("three-storey").unwrap();
        let generated = frame(3).unwrap();
        assert_eq!(generated.blocks.len(), built.blocks.len());
        for b in &built.blocks {
            let g = generated.blocks.iter().find(|g| g.name == b.name).unwrap();
            assert_eq!(g.vertices, b.vertices, "block {}", b.name);
            assert_eq!(g.material, b.material, "block {}", b.name);
        }
        assert_eq!(generated.connections.len(), built.connections.len());
        for c in &built.connections {
            assert!(generated.connections.contains(c), "connection {c:?}");
        }
        assert_eq!(generated.contacts, built.contacts);
        assert_eq!(generated.structure, built.structure);
    }

    #[test]
    fn wall_declares_every_touching_pair() {
        let s = wall(4).unwrap();
        // Courses of 4, 5, 4, 5 blocks, the slab and the ground.
        assert_eq!(s.blocks.len(), 18 + 2);
        // Head joints 3 + 4 + 3 + 4; bed joints: each course-to-course interface has
        // 8 overlapping pairs; the bottom course on the slab; the sliding joint.
        assert_eq!(s.contacts.len(), 14 + 3 * 8 + 4 + 1);
        // Steps land only on the sliding joint's events.
        let landing: Vec<&str> = s
            .contacts
            .iter()
            .filter(|c| c.locate_events)
            .map(|c| c.name.as_str())
            .collect();
        assert_eq!(landing, ["sliding-joint"]);
    }

    #[test]
    fn bad_sizes_are_clear_errors() {
        for name in ["frame:0", "frame:x", "wall:1000"] {
            let e = resolve_generated(name).unwrap().unwrap_err().to_string();
            assert!(e.contains("--scene"), "{name}: {e}");
        }
        assert!(resolve_generated("tower:3").is_none());
    }
}
