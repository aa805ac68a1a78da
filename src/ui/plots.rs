//! The live plots, synchronised with the time cursor (a vertical line at the time shown).

use egui_plot::{Legend, Line, Plot, PlotPoints, VLine};

use super::AppState;
use crate::ground_motion::STANDARD_GRAVITY;

const G: f64 = STANDARD_GRAVITY;

/// At most this many points per plotted line: about one per pixel of a plot panel,
/// and it keeps the frame time flat as a long run accumulates frames.
const MAX_POINTS: usize = 400;

fn series(state: &AppState, model: usize, f: impl Fn(&crate::sim::Probes) -> f64) -> Vec<[f64; 2]> {
    let frames = &state.timeline.frames;
    // Keep the extreme of each bucket so that peaks survive the decimation.
    let bucket = frames.len().div_ceil(MAX_POINTS).max(1);
    frames
        .chunks(bucket)
        .filter_map(|chunk| {
            chunk
                .iter()
                .filter_map(|fs| fs.models.get(model).map(|m| [fs.time, f(&m.probes)]))
                .max_by(|a, b| a[1].abs().total_cmp(&b[1].abs()))
        })
        .collect()
}

fn peak(points: &[[f64; 2]]) -> f64 {
    points.iter().fold(0.0_f64, |m, p| m.max(p[1].abs()))
}

fn line(name: &str, points: Vec<[f64; 2]>, color: egui::Color32) -> Line<'static> {
    Line::new(name.to_string(), PlotPoints::new(points))
        .color(color)
        .width(1.0)
}

const GROUND: egui::Color32 = egui::Color32::from_rgb(60, 60, 60);
const SLIDING: egui::Color32 = egui::Color32::from_rgb(0, 114, 178);
const FIXED: egui::Color32 = egui::Color32::from_rgb(213, 94, 0);
const EXACT: egui::Color32 = egui::Color32::from_rgb(0, 158, 115);

/// Draws every plot section.
pub fn plots_ui(state: &AppState, ui: &mut egui::Ui) {
    let t = state.play_time;
    let fixed = state
        .timeline
        .frames
        .first()
        .is_some_and(|f| f.models.len() > 1);
    let height = 150.0;
    egui::CollapsingHeader::new("accelerations (g)")
        .default_open(true)
        .show(ui, |ui| {
            let ground = series(state, 0, |p| p.ground_accel / G);
            let base = series(state, 0, |p| p.base_accel / G);
            let roof = series(state, 0, |p| p.roof_accel / G);
            let roof_fixed = if fixed {
                series(state, 1, |p| p.roof_accel / G)
            } else {
                Vec::new()
            };
            Plot::new("accel")
                .height(height)
                .legend(Legend::default())
                .show(ui, |p| {
                    p.line(line(
                        &format!("ground (peak {:.3})", peak(&ground)),
                        ground,
                        GROUND,
                    ));
                    p.line(line(
                        &format!("base, sliding (peak {:.3})", peak(&base)),
                        base,
                        egui::Color32::from_rgb(86, 180, 233),
                    ));
                    p.line(line(
                        &format!("roof, sliding (peak {:.3})", peak(&roof)),
                        roof,
                        SLIDING,
                    ));
                    if fixed {
                        p.line(line(
                            &format!("roof, fixed base (peak {:.3})", peak(&roof_fixed)),
                            roof_fixed,
                            FIXED,
                        ));
                    }
                    if let Some(e) = &state.timeline.exact {
                        let pts: Vec<[f64; 2]> = e
                            .time
                            .iter()
                            .zip(&e.roof_accel)
                            .map(|(a, b)| [*a, b / G])
                            .collect();
                        p.line(
                            line("roof, exact mass-spring", pts, EXACT)
                                .style(egui_plot::LineStyle::dashed_loose()),
                        );
                    }
                    p.vline(VLine::new("", t).color(egui::Color32::GRAY));
                });
        });
    egui::CollapsingHeader::new("slip and roof drift (m)")
        .default_open(true)
        .show(ui, |ui| {
            let slip = series(state, 0, |p| p.slip);
            let drift = series(state, 0, |p| p.drift);
            let drift_fixed = if fixed {
                series(state, 1, |p| p.drift)
            } else {
                Vec::new()
            };
            Plot::new("slip")
                .height(height)
                .legend(Legend::default())
                .show(ui, |p| {
                    p.line(line(
                        &format!("slip (peak {:.3})", peak(&slip)),
                        slip,
                        egui::Color32::from_rgb(204, 121, 167),
                    ));
                    p.line(line(
                        &format!("drift, sliding (peak {:.4})", peak(&drift)),
                        drift,
                        SLIDING,
                    ));
                    if fixed {
                        p.line(line(
                            &format!("drift, fixed base (peak {:.4})", peak(&drift_fixed)),
                            drift_fixed,
                            FIXED,
                        ));
                    }
                    if let Some(e) = &state.timeline.exact {
                        let s: Vec<[f64; 2]> =
                            e.time.iter().zip(&e.slip).map(|(a, b)| [*a, *b]).collect();
                        let d: Vec<[f64; 2]> =
                            e.time.iter().zip(&e.drift).map(|(a, b)| [*a, *b]).collect();
                        p.line(
                            line("slip, exact", s, EXACT)
                                .style(egui_plot::LineStyle::dashed_loose()),
                        );
                        p.line(
                            line("drift, exact", d, EXACT)
                                .style(egui_plot::LineStyle::dotted_loose()),
                        );
                    }
                    p.vline(VLine::new("", t).color(egui::Color32::GRAY));
                });
        });
    egui::CollapsingHeader::new("friction force against slip (hysteresis)")
        .default_open(false)
        .show(ui, |ui| {
            let pts: Vec<[f64; 2]> = state
                .timeline
                .frames
                .iter()
                .filter(|f| f.time <= t + 1e-9)
                .filter_map(|f| {
                    f.models
                        .first()
                        .map(|m| [m.probes.slip, m.probes.joint_force / 1e3])
                })
                .collect();
            Plot::new("hysteresis")
                .height(height)
                .x_axis_label("slip (m)")
                .y_axis_label("kN/m")
                .show(ui, |p| {
                    p.line(line("joint force", pts, SLIDING));
                });
        });
    egui::CollapsingHeader::new("Fourier spectra (ground, base)")
        .default_open(false)
        .show(ui, |ui| {
            let ground: Vec<f64> = series(state, 0, |p| p.ground_accel)
                .iter()
                .map(|p| p[1])
                .collect();
            let base: Vec<f64> = series(state, 0, |p| p.base_accel)
                .iter()
                .map(|p| p[1])
                .collect();
            let dt = state.timeline.config.as_ref().map_or(0.01, |c| c.frame_dt);
            let spec = |x: &[f64]| -> (Vec<[f64; 2]>, f64) {
                match crate::post::spectrum::fourier_amplitude(x, dt) {
                    Ok(s) => {
                        let pk = s.peak(0.1, 10.0).map_or(f64::NAN, |p| p.0);
                        (
                            s.freq_hz
                                .iter()
                                .zip(&s.amplitude)
                                .filter(|(f, _)| **f <= 10.0)
                                .map(|(f, a)| [*f, *a])
                                .collect(),
                            pk,
                        )
                    }
                    Err(_) => (Vec::new(), f64::NAN),
                }
            };
            let (g, gp) = spec(&ground);
            let (b, bp) = spec(&base);
            Plot::new("spectra")
                .height(height)
                .legend(Legend::default())
                .x_axis_label("Hz")
                .show(ui, |p| {
                    p.line(line(&format!("ground (peak {gp:.2} Hz)"), g, GROUND));
                    p.line(line(
                        &format!("base, sliding (peak {bp:.2} Hz)"),
                        b,
                        SLIDING,
                    ));
                });
        });
    egui::CollapsingHeader::new("where the energy goes (kJ/m)")
        .default_open(false)
        .show(ui, |ui| {
            let models = if fixed { 2 } else { 1 };
            for m in 0..models {
                let label = state.timeline.labels.get(m).cloned().unwrap_or_default();
                let e = |f: fn(&crate::dda::EnergyTerms) -> f64| {
                    series(state, m, move |p| f(&p.energy) / 1e3)
                };
                Plot::new(format!("energy{m}"))
                    .height(120.0)
                    .legend(Legend::default())
                    .show(ui, |p| {
                        p.line(line(
                            &format!("{label}: input"),
                            e(|x| x.input_work),
                            GROUND,
                        ));
                        p.line(line("kinetic", e(|x| x.kinetic), SLIDING));
                        p.line(line("strain", e(|x| x.strain), EXACT));
                        p.line(line("friction", e(|x| x.friction_dissipated), FIXED));
                        // Only scenes where blocks hit each other have this layer.
                        let impacts = e(|x| x.impact_dissipated);
                        if impacts.iter().any(|p| p[1] > 0.0) {
                            p.line(line(
                                "impacts",
                                impacts,
                                egui::Color32::from_rgb(200, 120, 40),
                            ));
                        }
                        p.line(line(
                            "numerical",
                            e(|x| x.residual()),
                            egui::Color32::from_rgb(150, 150, 150),
                        ));
                        p.vline(VLine::new("", t).color(egui::Color32::GRAY));
                    });
            }
        });
}
