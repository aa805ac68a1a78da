//! The fixed-base model of the last finished run, kept for the next one: the fixed base
//! does not depend on the sliding joint's friction (its joint is bonded: locked at every
//! step, its friction never consulted), so when only the friction changes — a friction
//! slider dragged — its frames and samples are played back instead of computed again,
//! and the sliding model has the second core to itself. Everything else that defines the
//! run (scene, record, scale, time step, integrator, damping, bearing, duration, frame
//! interval) is part of the key: any change to it computes the fixed base again.

use std::sync::Arc;

use super::{FrameSet, ModelFrame, Samples, SimConfig};
use crate::{Error, Result};

/// What the fixed-base model of `config` depends on: the configuration without the
/// sliding joint's friction (None: the run has no fixed-base model).
pub fn fixed_base_key(config: &SimConfig) -> Option<SimConfig> {
    config.compare_fixed.then(|| SimConfig {
        friction: None,
        friction_law: None,
        compare_friction: Vec::new(),
        ..config.clone()
    })
}

/// The most a recording holds, in parts of frames (blocks, contacts, bolts and
/// connections, each ~50–150 bytes): ~50 MB. The default scene's fixed base over El
/// Centro is ~2e5; a large wall's would be tens of millions, a copy of what the window
/// already holds, and is not kept.
const MAX_RECORDED_PARTS: usize = 500_000;

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
        self.samples.append(&mut samples.clone());
    }
}

/// A recording played back as model `model` of a run.
#[derive(Debug, Clone)]
pub struct Replay {
    recording: Arc<Recording>,
    /// The model it stands for.
    pub model: usize,
    next_frame: usize,
    next_row: usize,
}

impl Replay {
    /// Plays `recording` back from its start as model `model`.
    pub fn new(recording: Arc<Recording>, model: usize) -> Self {
        Self {
            recording,
            model,
            next_frame: 0,
            // The first row (t = 0) is the run's own: read off its model as built.
            next_row: 1,
        }
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
                    "the kept fixed-base run has no frame at t = {t} s (internal error: \
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
