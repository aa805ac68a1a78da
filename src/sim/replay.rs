//! The models of the last finished run, kept for the next one: a model is played back
//! frame by frame instead of computed again when nothing it depends on changed. The
//! models of a run share its settings (scene, record, scale, time step, integrator,
//! damping, bearing, duration, frame interval) and differ in the sliding joint's
//! friction: the main model has the run's, each compared model its own, and the fixed
//! base none (its joint is bonded: locked at every step, its friction never consulted).
//! So when a friction slider is dragged only the model with that friction is computed
//! again, and the others leave it the cores.

use std::sync::Arc;

use super::{FrameSet, ModelFrame, Samples, SimConfig};
use crate::model::friction::Friction;
use crate::{Error, Result};

/// Which model of a run it is, with the friction it has of its own.
#[derive(Debug, Clone, PartialEq)]
pub enum ModelRole {
    /// The main model: the run's friction coefficient and law.
    Main(Option<f64>, Option<Friction>),
    /// The same frame on the flat joint (next to pendulum bearings): the run's friction.
    Flat(Option<f64>, Option<Friction>),
    /// A model compared at another friction coefficient.
    ComparedFriction(f64),
    /// The fixed base.
    FixedBase,
}

/// What a model of a run depends on: the run's shared settings and its role.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelKey {
    shared: SimConfig,
    role: ModelRole,
}

impl ModelKey {
    /// The key of the model with `role` in a run of `config`.
    pub fn new(config: &SimConfig, role: ModelRole) -> Self {
        Self {
            shared: SimConfig {
                friction: None,
                friction_law: None,
                compare_friction: Vec::new(),
                ..config.clone()
            },
            role,
        }
    }
}

/// The most a recording of one model holds, in parts of frames (blocks, contacts, bolts
/// and connections, each ~50–150 bytes): ~40 MB. A three-storey frame over El Centro is
/// ~2e5; a large wall's would be tens of millions, a copy of what the window already
/// holds, and is not kept.
const MAX_RECORDED_PARTS: usize = 400_000;

/// A model's frames and full-rate samples over a whole run.
#[derive(Debug, Clone, Default)]
pub struct Recording {
    frames: Vec<ModelFrame>,
    samples: Samples,
    /// Parts of the frames so far (see [`MAX_RECORDED_PARTS`]).
    parts: usize,
}

impl Recording {
    /// Adds model `model`'s frame of each frame set; false (and the recording emptied)
    /// once it would hold more than [`MAX_RECORDED_PARTS`].
    pub fn add_frames(&mut self, frames: &[FrameSet], model: usize) -> bool {
        for frame in frames.iter().filter_map(|f| f.models.get(model)) {
            self.parts += frame.blocks.len()
                + frame.contacts.len()
                + frame.bolts.len()
                + frame.connections.len();
            if self.parts > MAX_RECORDED_PARTS {
                *self = Self::default();
                return false;
            }
            self.frames.push(frame.clone());
        }
        true
    }

    /// Adds rows of the model's samples.
    pub fn add_samples(&mut self, samples: &Samples) {
        self.samples.push_rows(samples, 0..samples.len());
    }
}

/// A recording played back as a model of a run.
#[derive(Debug, Clone)]
pub struct Replay {
    recording: Arc<Recording>,
    next_frame: usize,
    next_row: usize,
}

impl Replay {
    /// Plays `recording` back from its start.
    pub fn new(recording: Arc<Recording>) -> Self {
        Self {
            recording,
            next_frame: 0,
            // The first row (t = 0) is the run's own: read off its model as built.
            next_row: 1,
        }
    }

    /// The recording it plays.
    pub fn recording(&self) -> &Arc<Recording> {
        &self.recording
    }

    /// The next recorded frame, for frame time `t`, and the samples of the steps up to it
    /// appended to `samples`. A recording of a run with other frame times is refused.
    pub fn next(&mut self, t: f64, samples: &mut Samples) -> Result<ModelFrame> {
        let frame = self
            .recording
            .frames
            .get(self.next_frame)
            .filter(|f| (f.time - t).abs() <= 1e-9 * t.abs().max(1.0))
            .ok_or_else(|| {
                Error::Scene(format!(
                    "the kept run of a model has no frame at t = {t} s (internal error: \
                     its key did not cover the frame times)"
                ))
            })?;
        self.next_frame += 1;
        let recorded = &self.recording.samples;
        // The rows of the steps up to this frame: those at its time or before (the same
        // values to the bit: both were read off the same steps).
        let end = recorded
            .time
            .partition_point(|&s| s <= frame.time)
            .max(self.next_row);
        samples.push_rows(recorded, self.next_row..end);
        self.next_row = end;
        Ok(frame.clone())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A recording grows frame by frame up to its bound, then gives up and lets go of
    /// what it held (a large wall's fixed base is not kept).
    #[test]
    fn a_recording_stops_at_its_bound() {
        let config = SimConfig {
            scene: "wall:10".into(),
            ..SimConfig::default()
        };
        let frames = [super::super::prepare(&config).unwrap().frame_set()];
        let parts = {
            let f = &frames[0].models[0];
            f.blocks.len() + f.contacts.len() + f.bolts.len() + f.connections.len()
        };
        assert!(parts > 100, "{parts}");
        let mut recording = Recording::default();
        let fitting = MAX_RECORDED_PARTS / parts;
        for _ in 0..fitting {
            assert!(recording.add_frames(&frames, 0));
        }
        assert_eq!(recording.frames.len(), fitting);
        assert!(!recording.add_frames(&frames, 0));
        assert!(recording.frames.is_empty() && recording.parts == 0);
    }
}
