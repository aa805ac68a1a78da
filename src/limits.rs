//! The limits of what slidebase accepts, in one place (the README's "Limits" section lists
//! them). Each is checked before anything is allocated or run, and an input beyond one is
//! refused with the number that was asked for.
//!
//! Two kinds: *resources* (sizes, counts, file reads) keep a mistyped number from
//! allocating terabytes or running for a year; *ranges* keep physical quantities where
//! double-precision arithmetic and the solver's tolerances hold (a density of 1e300 or a
//! gravity of 1e10 m/s² overflows the products the solver forms).

/// Time steps a run may take (duration / Δt, or the exact model's propagation steps)
/// without `--confirm-large` (10⁸ DDA steps of the two-block model take about 6 minutes).
pub const MAX_STEPS: f64 = 1e8;

/// Samples a ground-motion record may have (10⁷: 28 h at 100 Hz).
pub const MAX_RECORD_SAMPLES: usize = 10_000_000;

/// Bytes read from a record file (256 MiB, ample for 10⁷ samples as text).
pub const MAX_RECORD_FILE_BYTES: u64 = 256 << 20;

/// Sample spacing of a record, s: from 10 µs to 1 s.
pub const RECORD_DT_RANGE: (f64, f64) = (1e-5, 1.0);

/// Largest |acceleration| of a record or a harmonic input, g (the largest ever recorded is
/// about 4 g).
pub const MAX_ACCEL_G: f64 = 20.0;

/// Smallest amplitude of a harmonic input, g: below it the response is lost in the
/// solver's rounding, and ratios to the input become meaningless.
pub const MIN_AMPLITUDE_G: f64 = 1e-4;

/// Bytes read from a scene file (16 MiB: about 10⁵ blocks written out).
pub const MAX_SCENE_FILE_BYTES: u64 = 16 << 20;

/// Blocks in a scene.
pub const MAX_BLOCKS: usize = 10_000;

/// Vertices of one polygon.
pub const MAX_POLYGON_VERTICES: usize = 1_000;

/// Vertices of all the polygons of a scene.
pub const MAX_SCENE_VERTICES: usize = 200_000;

/// Contacts, bolts, connections, fixed points and point loads, each.
pub const MAX_ELEMENTS: usize = 100_000;

/// Largest |coordinate| of any point of a scene, m.
pub const MAX_COORDINATE_M: f64 = 1e6;

/// The structure (every block but the ground) may span at most this many times its
/// smallest block: the solver's contact search distance and tolerances are fractions of
/// the structure's size, so a structure far larger than its blocks loses its contacts.
pub const MAX_SPAN_RATIO: f64 = 1e4;

/// Density of a block, kg/m³ (per unit thickness; lumped floor masses reach 10⁶).
pub const DENSITY_RANGE: (f64, f64) = (1e-6, 1e12);

/// Young's modulus, Pa.
pub const YOUNGS_MODULUS_RANGE: (f64, f64) = (1.0, 1e18);

/// Penalty springs and bolt stiffnesses, N/m.
pub const STIFFNESS_RANGE: (f64, f64) = (1e-6, 1e20);

/// Gravity, m/s² (0 is allowed only without contacts: a joint without weight carries no
/// friction).
pub const MAX_GRAVITY: f64 = 1e3;

/// Largest finite friction coefficient (`inf` in a scene file means "never slides").
pub const MAX_FRICTION: f64 = 1e3;

/// Largest point load, N per unit thickness.
pub const MAX_FORCE_N: f64 = 1e15;

/// Frequency of a harmonic input, Hz.
pub const FREQUENCY_RANGE_HZ: (f64, f64) = (1e-4, 1e3);

/// Time steps per period: fewer than [`WARN_STEPS_PER_PERIOD`] is warned about, fewer
/// than [`MIN_STEPS_PER_PERIOD`] refused (the motion cannot be represented at all).
pub const WARN_STEPS_PER_PERIOD: f64 = 10.0;

/// See [`WARN_STEPS_PER_PERIOD`].
pub const MIN_STEPS_PER_PERIOD: f64 = 2.0;

/// Rows of a time history kept in memory; beyond it every other row is dropped and the
/// recording interval doubled.
pub const MAX_HISTORY_ROWS: usize = 1_000_000;

/// Runs in one sweep (the whole grid, both models).
pub const MAX_SWEEP_RUNS: usize = 1_000_000;

/// Values in one list of a sweep (`--alpha`, `--friction`, `--freq-ratios`).
pub const MAX_LIST_VALUES: usize = 100_000;

/// Bytes read from a sweep table by `merge`.
pub const MAX_TABLE_FILE_BYTES: u64 = 256 << 20;

/// Repeats of a benchmark run.
pub const MAX_REPEATS: usize = 1_000;

/// Worker threads.
pub const MAX_JOBS: usize = 1_024;

/// Width and height of a rendered picture, pixels.
pub const MAX_IMAGE_SIDE: u32 = 8_192;

/// Smallest width and height of a rendered picture, pixels (room for the titles and the
/// legend).
pub const MIN_IMAGE_SIDE: u32 = 64;

/// Reads a text file of at most `max_bytes`, refusing what is not a regular file (a pipe,
/// FIFO, device or folder could be endless or block forever). `what` names the kind of
/// file in the messages. Errors name the file.
pub fn read_text(path: &std::path::Path, max_bytes: u64, what: &str) -> crate::Result<String> {
    use std::io::Read;
    let fail = |kind: std::io::ErrorKind, message: String| {
        crate::Error::io(path, std::io::Error::new(kind, message))
    };
    let meta = std::fs::metadata(path).map_err(|e| crate::Error::io(path, e))?;
    if !meta.is_file() {
        return Err(fail(
            std::io::ErrorKind::InvalidInput,
            format!("not a regular file (a folder, pipe, FIFO or device); a {what} must be a file"),
        ));
    }
    if meta.len() > max_bytes {
        return Err(fail(
            std::io::ErrorKind::InvalidInput,
            format!(
                "{} bytes; a {what} may have at most {max_bytes} bytes (see the README's Limits)",
                meta.len()
            ),
        ));
    }
    let file = std::fs::File::open(path).map_err(|e| crate::Error::io(path, e))?;
    let mut bytes = Vec::new();
    // The size can change between the check and the read: never read more than the limit.
    file.take(max_bytes + 1)
        .read_to_end(&mut bytes)
        .map_err(|e| crate::Error::io(path, e))?;
    if bytes.len() as u64 > max_bytes {
        return Err(fail(
            std::io::ErrorKind::InvalidInput,
            format!("grew beyond {max_bytes} bytes while being read"),
        ));
    }
    String::from_utf8(bytes).map_err(|e| {
        fail(
            std::io::ErrorKind::InvalidData,
            format!(
                "not UTF-8 text (invalid byte at offset {}); a {what} is a text file",
                e.utf8_error().valid_up_to()
            ),
        )
    })
}

/// The deformation exaggeration a picture or replay may be drawn with (1: true scale; the
/// automatic choice lies in 1…1000). Beyond it the drift leaves the picture and the
/// single-precision vertices lose the shape.
pub const EXAGGERATION_RANGE: (f64, f64) = (0.01, 1e4);
