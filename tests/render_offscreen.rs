//! The renderer, offscreen, as a person would check a picture: blocks where the blocks
//! are, the slip arrow on the side the base slipped to, locked and sliding springs in their
//! colours, and a reference image of the two-block scene.
//!
//! These need a graphics adapter (Mesa's software Vulkan/GL drivers do). In CI (`CI` set)
//! a missing adapter fails the tests; elsewhere they are skipped with a loud message.

#![cfg(feature = "gui")]
#![allow(clippy::unwrap_used, clippy::expect_used)]

use slidebase::render::offscreen::{FORMAT, Gpu, render_rgba};
use slidebase::render::{ColorBy, Layers, PanelView, Renderer, SceneView, ViewBox};
use slidebase::sim::{BlockFrame, ContactFrame, ModelFrame, Probes};

fn gpu() -> Option<Gpu> {
    match Gpu::new() {
        Ok(g) => Some(g),
        Err(e) if std::env::var_os("CI").is_some() => {
            panic!("CI must have a graphics adapter: {e}")
        }
        Err(e) => {
            eprintln!("\n*** SKIPPING offscreen render test: {e} ***\n");
            None
        }
    }
}

fn rect_block(x0: f32, x1: f32, y0: f32, y1: f32, ground: bool) -> BlockFrame {
    let v = vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]];
    BlockFrame {
        vertices: v.clone(),
        rigid: v,
        stress: [0.0; 3],
        strain: [0.0; 3],
        is_ground: ground,
    }
}

/// Ground from y = −1 to 0, a 2 m × 1 m block on it centred at x = 0, contacts at its
/// corners (left locked, right sliding), the base slipped by `slip`.
fn frame(slip: f64) -> ModelFrame {
    ModelFrame {
        time: 1.0,
        blocks: vec![
            rect_block(-50.0, 50.0, -1.0, 0.0, true),
            rect_block(-1.0, 1.0, 0.0, 1.0, false),
        ],
        single_body: false,
        contacts: vec![
            ContactFrame {
                point: [-1.0, 0.0],
                rigid: [-1.0, 0.0],
                tangent: [-1.0, 0.0],
                along_edge: -1.0,
                normal_force: 1.0,
                state: 1,
            },
            ContactFrame {
                point: [1.0, 0.0],
                rigid: [1.0, 0.0],
                tangent: [-1.0, 0.0],
                along_edge: 1.0,
                normal_force: 1.0,
                state: 2,
            },
        ],
        base: 1,
        base_start: vec![
            [-1.0 - slip as f32, 0.0],
            [1.0 - slip as f32, 0.0],
            [1.0 - slip as f32, 1.0],
            [-1.0 - slip as f32, 1.0],
        ],
        bolts: vec![],
        connections: vec![],
        probes: Probes {
            slip,
            ..Probes::default()
        },
    }
}

struct Image {
    w: u32,
    px: Vec<u8>,
}

impl Image {
    fn at(&self, x: u32, y: u32) -> [u8; 3] {
        let i = ((y * self.w + x) * 4) as usize;
        [self.px[i], self.px[i + 1], self.px[i + 2]]
    }
}

/// Renders one panel of `frame` at 400×300 with the world window [half 4 m, y −1…3 m]:
/// 100 px per metre, x = 0 at column 200, y = 0 at row 225.
fn render(gpu: &Gpu, f: &ModelFrame, layers: Layers) -> Image {
    let slip = f.probes.slip as f32;
    let view = SceneView {
        panels: vec![PanelView {
            frame: f,
            rect: [0.0, 0.0, 400.0, 300.0],
            view: ViewBox {
                centre: [0.0, 0.75],
                metres_per_pixel: 0.01,
            },
            slip_range: [slip.min(0.0), slip.max(0.0)],
            close_up: false,
        }],
        exaggeration: 1.0,
        color_by: ColorBy::Material,
        color_max: 1.0,
        layers,
    };
    let mut renderer = Renderer::new(&gpu.device, FORMAT);
    let px = render_rgba(gpu, &mut renderer, &view, 400, 300).unwrap();
    Image { w: 400, px }
}

fn close(a: [u8; 3], b: [u8; 3], tol: i32) -> bool {
    (0..3).all(|k| (a[k] as i32 - b[k] as i32).abs() <= tol)
}

fn srgb(c: [f32; 4]) -> [u8; 3] {
    let f = |v: f32| {
        let v = v.clamp(0.0, 1.0);
        let s = if v <= 0.0031308 {
            12.92 * v
        } else {
            1.055 * v.powf(1.0 / 2.4) - 0.055
        };
        (s * 255.0).round() as u8
    };
    [f(c[0]), f(c[1]), f(c[2])]
}

#[test]
fn blocks_ground_and_sky_are_where_they_should_be() {
    let Some(gpu) = gpu() else { return };
    let img = render(
        &gpu,
        &frame(0.0),
        Layers {
            contacts: false,
            slip: false,
            ..Layers::default()
        },
    );
    // 100 px per metre, x = 0 at column 200; the block spans columns 100…300 and rows
    // 125…225 (y = 1…0); the ground is below row 225.
    let block = img.at(200, 175);
    let sky = img.at(200, 40);
    let ground = img.at(250, 270); // between the metre marks
    let material = srgb([0.72, 0.74, 0.78, 1.0]);
    assert!(
        close(block, material, 6),
        "block pixel {block:?}, expected {material:?}"
    );
    assert!(
        close(ground, srgb([0.42, 0.33, 0.25, 1.0]), 6),
        "ground pixel {ground:?}"
    );
    assert!(sky[2] > 230 && sky[0] > 220, "sky pixel {sky:?}");
    // Beside the block at its mid-height: sky, not block.
    assert!(
        close(img.at(60, 175), sky, 3),
        "left of the block {:?}",
        img.at(60, 175)
    );
    assert!(close(img.at(340, 175), sky, 3));
}

#[test]
fn slip_arrow_points_the_way_the_base_slipped() {
    let Some(gpu) = gpu() else { return };
    let layers = Layers {
        contacts: false,
        ..Layers::default()
    };
    let red = |img: &Image, x0: u32, x1: u32| -> usize {
        (x0..x1)
            .flat_map(|x| (200..225).map(move |y| (x, y)))
            .filter(|&(x, y)| {
                let p = img.at(x, y);
                p[0] > 180 && p[1] < 100 && p[2] < 100
            })
            .count()
    };
    // Slipped +0.8 m: the mark where the base's left end (x = −1 m, column 100) started is
    // 0.8 m further left (column 20), and the arrow runs from it to the base.
    let right = render(&gpu, &frame(0.8), layers);
    assert!(
        red(&right, 25, 95) > 40,
        "arrow left of the base when slip > 0"
    );
    assert!(red(&right, 210, 300) < 5, "nothing to the right");
    // Slipped −0.8 m: it started 0.8 m to the right (column 180); the arrow points left.
    let left = render(&gpu, &frame(-0.8), layers);
    assert!(
        red(&left, 105, 175) > 40,
        "arrow right of the base's end when slip < 0"
    );
    assert!(red(&left, 20, 95) < 5);
}

#[test]
fn locked_and_sliding_springs_have_their_colours() {
    let Some(gpu) = gpu() else { return };
    let img = render(
        &gpu,
        &frame(0.0),
        Layers {
            slip: false,
            ..Layers::default()
        },
    );
    let count = |x0: u32, x1: u32, c: [u8; 3]| -> usize {
        (x0..x1)
            .flat_map(|x| (215..250).map(move |y| (x, y)))
            .filter(|&(x, y)| close(img.at(x, y), c, 40))
            .count()
    };
    let locked = srgb(slidebase::render::geometry::LOCKED);
    let sliding = srgb(slidebase::render::geometry::SLIDING);
    // The left corner (x = −1 m → column 100) is locked, the right (column 300) sliding.
    assert!(
        count(80, 120, locked) > 20,
        "locked spring at the left corner"
    );
    assert!(count(80, 120, sliding) < 3);
    assert!(
        count(280, 320, sliding) > 20,
        "sliding spring at the right corner"
    );
    assert!(count(280, 320, locked) < 3);
}

/// The built-in two-block scene at t = 1.5 s against a reference picture: at most 1 % of
/// the pixels may differ by more than 24 levels (software rasterisers differ in
/// anti-aliasing at edges, not in what is drawn).
#[test]
fn two_block_scene_matches_the_reference_image() {
    let Some(_gpu) = gpu() else { return };
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("two_block.png");
    let config = slidebase::sim::SimConfig {
        scene: "two-block".into(),
        ..Default::default()
    };
    let options = slidebase::export::PictureOptions {
        width: 640,
        height: 360,
        ..Default::default()
    };
    slidebase::export::render_picture(&config, 1.5, &options, &path, None).unwrap();
    let reference = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/reference/two_block_t1.5.png");
    if std::env::var_os("SLIDEBASE_UPDATE_REFERENCE").is_some() {
        std::fs::create_dir_all(reference.parent().unwrap()).unwrap();
        std::fs::copy(&path, &reference).unwrap();
    }
    let decode = |p: &std::path::Path| {
        let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(p).unwrap()));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        (info.width, info.height, buf)
    };
    let (w, h, got) = decode(&path);
    let (rw, rh, want) = decode(&reference);
    assert_eq!((w, h), (rw, rh));
    let differing = got
        .chunks(4)
        .zip(want.chunks(4))
        .filter(|(a, b)| (0..3).any(|k| (a[k] as i32 - b[k] as i32).abs() > 24))
        .count();
    let fraction = differing as f64 / (w * h) as f64;
    assert!(
        fraction < 0.01,
        "{:.2} % of the pixels differ",
        100.0 * fraction
    );
}
