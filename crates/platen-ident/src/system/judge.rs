//! The identified loop judged: run on each record's command
//! ([`platen_integrate::forward_closed_loop`], RK4 at the step `platen simulate` takes for the
//! printed scenario, from rest at the command's first sample) and compared with what the
//! table did, side by side with two models that need no physics:
//!
//! * **a linear black box**: one FIR filter per acceleration channel from the command's
//!   acceleration (its central second difference) to the channel, [`BLACK_BOX_LENGTH_S`]
//!   long, fitted by least squares on the *same* records the physical model was fitted on
//!   (the command taken at rest before its first sample);
//! * **perfect tracking**: the table does exactly what it is told (its acceleration is the
//!   command's, its displacement the command).
//!
//! The accelerations are compared in the band the command drives: both sides through the
//! same zero-phase low-pass at [`JUDGE_LOWPASS_HZ`] (fourth-order Butterworth, forward and
//! backward; at most 0.4 of the sample rate), since what lies above (hydraulic noise, pumps,
//! an accelerometer's own resonances) is in no model's reach. The error is an NRMSE: the RMS
//! of recorded less predicted over the recorded RMS, both in that band. The displacement is
//! compared as recorded.

use nalgebra::{DMatrix, DVector};
use platen_integrate::{
    forward_closed_loop, LoopMethod, LoopRun, Motion, Sample, SampleSink, State,
};
use platen_model::Specimen;
use platen_signal::{ButterworthLowpass, ZeroPhaseFilter};

use super::plant::IdentifiedPlant;
use super::SystemRecord;

/// Upper edge of the band the accelerations are compared in, Hz.
pub const JUDGE_LOWPASS_HZ: f64 = 30.0;
/// Length of the black box's FIR filters, s (long enough for a lightly damped specimen mode
/// of a few hertz to ring down through most of its response).
pub const BLACK_BOX_LENGTH_S: f64 = 1.25;
/// Most taps of a black-box filter.
pub const MAX_BLACK_BOX_TAPS: usize = 512;

/// Errors of a model that needs no physics on one record.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Baseline {
    /// Table acceleration NRMSE in the band.
    pub acceleration_nrmse: f64,
    /// Each storey's acceleration NRMSE in the band (empty when not predicted).
    pub storey_acceleration_nrmse: Vec<f64>,
    /// Displacement NRMSE (absent when not predicted).
    pub displacement_nrmse: Option<f64>,
}

/// The series behind one [`Prediction`], for figures.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct PredictionSeries {
    /// Sample times, s.
    pub t_s: Vec<f64>,
    /// The command, m.
    pub command_u_m: Vec<f64>,
    /// Recorded displacement, m.
    pub recorded_u_m: Vec<f64>,
    /// Predicted displacement, m.
    pub predicted_u_m: Vec<f64>,
    /// Recorded table acceleration in the band, m/s².
    pub recorded_a_m_s2: Vec<f64>,
    /// Predicted table acceleration in the band, m/s².
    pub predicted_a_m_s2: Vec<f64>,
    /// The black box's table acceleration in the band, m/s² (empty without one).
    pub black_box_a_m_s2: Vec<f64>,
    /// The command's acceleration in the band (perfect tracking), m/s².
    pub command_a_m_s2: Vec<f64>,
    /// Recorded and predicted storey accelerations in the band, m/s², bottom first.
    pub storeys: Vec<(Vec<f64>, Vec<f64>)>,
}

/// The identified loop run on one record's command.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Prediction {
    /// The record's name.
    pub name: String,
    /// Whether the record was used in the fit.
    pub fitted: bool,
    /// RMS of the recorded table acceleration, m/s².
    pub acceleration_rms_m_s2: f64,
    /// RMS of recorded less predicted table acceleration, m/s² (all frequencies).
    pub acceleration_rms_error_m_s2: f64,
    /// The accelerometer's noise estimated from the record (RMS of the second difference
    /// over √6: an upper bound, the signal's own curvature included), m/s².
    pub acceleration_noise_m_s2: f64,
    /// RMS of the recorded displacement, m.
    pub displacement_rms_m: f64,
    /// RMS of recorded less predicted displacement, m.
    pub displacement_rms_error_m: f64,
    /// The identified loop's errors (table and storey accelerations in the band,
    /// displacement).
    pub model: Baseline,
    /// The linear black box's errors (absent when it could not be fitted).
    pub black_box: Option<Baseline>,
    /// Perfect tracking's errors.
    pub perfect_tracking: Baseline,
    /// The series, for figures.
    #[serde(skip)]
    pub series: PredictionSeries,
}

/// Medians over the held-out records.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct HeldOutMedians {
    /// Records held out.
    pub records: usize,
    /// The identified loop's table acceleration NRMSE.
    pub model_acceleration_nrmse: f64,
    /// The black box's.
    pub black_box_acceleration_nrmse: Option<f64>,
    /// Perfect tracking's.
    pub perfect_tracking_acceleration_nrmse: f64,
    /// The identified loop's displacement NRMSE.
    pub model_displacement_nrmse: f64,
    /// Perfect tracking's displacement NRMSE.
    pub perfect_tracking_displacement_nrmse: f64,
    /// Whether the identified loop predicts the table acceleration at least as well as the
    /// black box.
    pub model_beats_black_box: Option<bool>,
}

/// The judgement of the identified loop.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Judgement {
    /// Upper edge of the band the accelerations are compared in, Hz.
    pub band_hz: f64,
    /// Taps of the black box's filters.
    pub black_box_taps: usize,
    /// RK4 steps per controller period of the runs (those `platen simulate` takes for the
    /// printed scenario).
    pub steps_per_period: u32,
    /// Every record, fitted and held out, whose run succeeded.
    pub predictions: Vec<Prediction>,
    /// The records whose run failed, with the integrator's reason.
    pub failed: Vec<(String, String)>,
    /// Medians over the held-out records (absent when none is held out).
    pub held_out: Option<HeldOutMedians>,
}

/// A linear black box: an FIR filter from an input to an output.
#[derive(Debug, Clone, PartialEq)]
pub struct BlackBox {
    /// The filter's taps, newest input first.
    pub taps: Vec<f64>,
}

impl BlackBox {
    /// The output for `input` (taken as 0 before its first sample).
    pub fn predict(&self, input: &[f64]) -> Vec<f64> {
        (0..input.len())
            .map(|i| {
                self.taps
                    .iter()
                    .enumerate()
                    .take(i + 1)
                    .map(|(k, h)| h * input[i - k])
                    .sum()
            })
            .collect()
    }
}

/// Fits an FIR filter of `taps` taps from `inputs[r]` to `outputs[r]` over every record `r`
/// by least squares (inputs taken as 0 before their first sample). The normal equations are
/// built from lagged products in `O(n·taps)` and solved by Cholesky with a ridge of `1e-9` of
/// their mean diagonal; `None` when they are singular or the data too short.
pub fn fir_black_box(inputs: &[&[f64]], outputs: &[&[f64]], taps: usize) -> Option<BlackBox> {
    if taps == 0 || inputs.len() != outputs.len() {
        return None;
    }
    let mut r = DMatrix::<f64>::zeros(taps, taps);
    let mut b = DVector::<f64>::zeros(taps);
    let mut rows = 0usize;
    for (x, y) in inputs.iter().zip(outputs) {
        let n = x.len().min(y.len());
        rows += n;
        // Lagged products S_d = Σ_{m=0}^{n−1−d} x[m]·x[m+d]; the entry (j, k) of XᵀX (rows
        // i = 0 … n−1, x[i−j] with x = 0 before 0) is S_d less the terms past the end:
        // Σ_{m=n−max(j,k)}^{n−1−d} x[m]·x[m+d].
        let s: Vec<f64> = (0..taps)
            .map(|d| (0..n.saturating_sub(d)).map(|m| x[m] * x[m + d]).sum())
            .collect();
        for j in 0..taps {
            for k in j..taps {
                let d = k - j;
                let mut v = s[d];
                let from = n.saturating_sub(k);
                for m in from..n.saturating_sub(d) {
                    v -= x[m] * x[m + d];
                }
                r[(j, k)] += v;
            }
            b[j] += (j..n).map(|i| y[i] * x[i - j]).sum::<f64>();
        }
    }
    if rows <= 4 * taps {
        return None;
    }
    for j in 0..taps {
        for k in 0..j {
            r[(j, k)] = r[(k, j)];
        }
    }
    let ridge = 1e-9 * r.trace() / taps as f64;
    for j in 0..taps {
        r[(j, j)] += ridge;
    }
    let h = r.cholesky()?.solve(&b);
    Some(BlackBox {
        taps: h.iter().copied().collect(),
    })
}

/// Collects the table's and storeys' motion of a run.
#[derive(Default)]
struct Collect {
    u: Vec<f64>,
    a: Vec<f64>,
    storeys: Vec<Vec<f64>>,
}

impl SampleSink for Collect {
    fn accept(&mut self, s: &Sample) {
        self.u.push(s.u_m);
        self.a.push(s.a_m_s2);
        if let Some(sp) = &s.specimen {
            self.storeys.resize(sp.storeys, Vec::new());
            for (k, st) in self.storeys.iter_mut().enumerate() {
                st.push(sp.a_m_s2[k]);
            }
        }
    }
}

/// [`platen_signal::metrics::rms`] of a computed series.
fn rms(x: impl Iterator<Item = f64>) -> f64 {
    platen_signal::metrics::rms(&x.collect::<Vec<f64>>())
}

fn nrmse(recorded: &[f64], predicted: &[f64]) -> f64 {
    let e = rms(recorded.iter().zip(predicted).map(|(a, b)| a - b));
    let r = rms(recorded.iter().copied());
    if r > 0.0 {
        e / r
    } else {
        f64::NAN
    }
}

fn median(mut x: Vec<f64>) -> f64 {
    x.retain(|v| v.is_finite());
    if x.is_empty() {
        return f64::NAN;
    }
    x.sort_by(f64::total_cmp);
    let n = x.len();
    if n % 2 == 1 {
        x[n / 2]
    } else {
        0.5 * (x[n / 2 - 1] + x[n / 2])
    }
}

/// The black boxes of the table and each storey, fitted on the `fitted` records.
fn black_boxes(
    records: &[SystemRecord],
    periods: &[f64],
    fitted: &[usize],
    taps: usize,
) -> Vec<Option<BlackBox>> {
    let inputs: Vec<Vec<f64>> = fitted
        .iter()
        .map(|&i| super::central(&records[i].command_u_m, periods[i]).1)
        .collect();
    let ins: Vec<&[f64]> = inputs.iter().map(Vec::as_slice).collect();
    let storeys = fitted
        .iter()
        .map(|&i| records[i].storey_a_m_s2.len())
        .min()
        .unwrap_or(0);
    let mut out = Vec::with_capacity(1 + storeys);
    let table: Option<Vec<&[f64]>> = fitted
        .iter()
        .map(|&i| records[i].a_m_s2.as_deref())
        .collect();
    out.push(table.and_then(|t| fir_black_box(&ins, &t, taps)));
    for s in 0..storeys {
        let outs: Vec<&[f64]> = fitted
            .iter()
            .map(|&i| records[i].storey_a_m_s2[s].as_slice())
            .collect();
        out.push(fir_black_box(&ins, &outs, taps));
    }
    out
}

/// Runs the identified loop on every record's command and judges it (module docs); `None`
/// without an identified system and model, or when no record has a table acceleration.
pub(crate) fn judge(
    records: &[SystemRecord],
    periods: &[f64],
    fitted: &[usize],
    plant: &IdentifiedPlant,
) -> Option<Judgement> {
    let (system, model) = (plant.system.as_ref()?, plant.model.as_ref()?);
    let model = model.build().ok()?;
    let h = periods[fitted[0]];
    let taps = ((BLACK_BOX_LENGTH_S / h).round() as usize).clamp(8, MAX_BLACK_BOX_TAPS);
    let boxes = black_boxes(records, periods, fitted, taps);
    let band_hz = JUDGE_LOWPASS_HZ.min(0.4 * 0.5 / h);
    // The step `platen simulate` takes for the printed scenario (its stroke limit, the
    // platen and specimen as the payload), so the judgement is what `simulate` would show.
    let payload = plant.specimen.as_ref().map_or(0.0, Specimen::total_mass_kg);
    let steps_per_period = system.default_steps_per_period(
        plant.model.as_ref()?.effective_mass_kg + payload,
        super::plant::stroke_limit_m(system),
    );
    let ctx = Judge {
        model: &model,
        system,
        plant,
        periods,
        fitted,
        boxes: &boxes,
        band_hz,
        steps_per_period,
    };
    let mut predictions = Vec::new();
    let mut failed = Vec::new();
    for (i, r) in records.iter().enumerate() {
        match predict(&ctx, i, r) {
            Ok(Some(p)) => predictions.push(p),
            Ok(None) => {}
            Err(f) => failed.push(f),
        }
    }
    if predictions.is_empty() && failed.is_empty() {
        return None;
    }
    let held_out = medians(&predictions);
    Some(Judgement {
        band_hz,
        black_box_taps: taps,
        steps_per_period,
        predictions,
        failed,
        held_out,
    })
}

/// What [`judge`] runs every record with.
struct Judge<'a> {
    model: &'a platen_model::IdentifiedModel,
    system: &'a platen_system::TableSystem,
    plant: &'a IdentifiedPlant,
    periods: &'a [f64],
    fitted: &'a [usize],
    boxes: &'a [Option<BlackBox>],
    band_hz: f64,
    steps_per_period: u32,
}

/// Record `i`'s prediction by the identified loop, the black box and perfect tracking; `None`
/// when it has no table acceleration (or a filter or command cannot be made for it), `Err`
/// with the record's name and why when the loop's run fails.
fn predict(
    ctx: &Judge<'_>,
    i: usize,
    r: &SystemRecord,
) -> Result<Option<Prediction>, (String, String)> {
    let Some(a_rec) = r.a_m_s2.as_ref() else {
        return Ok(None);
    };
    let hi = ctx.periods[i];
    let Ok(lp) = ButterworthLowpass::new(4, ctx.band_hz.min(0.4 * 0.5 / hi), 1.0 / hi) else {
        return Ok(None);
    };
    let band = |x: &[f64]| lp.apply(x).ok();
    let Ok(command) = Motion::from_displacement(r.t_s.clone(), r.command_u_m.clone()) else {
        return Ok(None);
    };
    let sink = run_loop(ctx, r, &command)?;
    let n = a_rec.len();
    let a_ref = super::central(&r.command_u_m, hi).1;
    let (Some(rec_b), Some(pred_b), Some(cmd_b)) = (band(a_rec), band(&sink.a), band(&a_ref))
    else {
        return Ok(None);
    };
    let box_b = ctx.boxes[0].as_ref().and_then(|b| band(&b.predict(&a_ref)));
    let Some(StoreyFits {
        storeys,
        model: storey_model,
        black_box: storey_box,
    }) = storey_fits(ctx, r, &sink, &band, &a_ref)
    else {
        return Ok(None);
    };
    let noise = rms((1..n - 1).map(|j| a_rec[j + 1] - 2.0 * a_rec[j] + a_rec[j - 1])) / 6f64.sqrt();
    Ok(Some(Prediction {
        name: r.name.clone(),
        fitted: ctx.fitted.contains(&i),
        acceleration_rms_m_s2: rms(a_rec.iter().copied()),
        acceleration_rms_error_m_s2: rms(a_rec.iter().zip(&sink.a).map(|(x, y)| x - y)),
        acceleration_noise_m_s2: noise,
        displacement_rms_m: rms(r.u_m.iter().copied()),
        displacement_rms_error_m: rms(r.u_m.iter().zip(&sink.u).map(|(x, y)| x - y)),
        model: Baseline {
            acceleration_nrmse: nrmse(&rec_b, &pred_b),
            storey_acceleration_nrmse: storey_model,
            displacement_nrmse: Some(nrmse(&r.u_m, &sink.u)),
        },
        black_box: box_b.as_ref().map(|b| Baseline {
            acceleration_nrmse: nrmse(&rec_b, b),
            storey_acceleration_nrmse: storey_box,
            displacement_nrmse: None,
        }),
        perfect_tracking: Baseline {
            acceleration_nrmse: nrmse(&rec_b, &cmd_b),
            storey_acceleration_nrmse: Vec::new(),
            displacement_nrmse: Some(nrmse(&r.u_m, &r.command_u_m)),
        },
        series: PredictionSeries {
            t_s: r.t_s.clone(),
            command_u_m: r.command_u_m.clone(),
            recorded_u_m: r.u_m.clone(),
            predicted_u_m: sink.u,
            recorded_a_m_s2: rec_b,
            predicted_a_m_s2: pred_b,
            black_box_a_m_s2: box_b.unwrap_or_default(),
            command_a_m_s2: cmd_b,
            storeys,
        },
    }))
}

/// The identified loop run on record `r`'s `command` from rest at its first sample; `Err`
/// with the record's name and why when the run fails.
fn run_loop(
    ctx: &Judge<'_>,
    r: &SystemRecord,
    command: &Motion,
) -> Result<Collect, (String, String)> {
    let run = LoopRun {
        system: ctx.system,
        specimen: ctx.plant.specimen.as_ref(),
        command,
        method: LoopMethod::Rk4 {
            steps_per_period: ctx.steps_per_period,
        },
        initial: State {
            u_m: r.command_u_m[0],
            v_m_s: 0.0,
        },
    };
    let mut sink = Collect::default();
    if let Err(e) = forward_closed_loop(ctx.model, &run, r.t_s.len(), &mut sink) {
        return Err((r.name.clone(), e.to_string()));
    }
    Ok(sink)
}

/// The storeys' accelerations of a record, recorded and predicted, in the band.
struct StoreyFits {
    /// Each storey's `(recorded, predicted)`.
    storeys: Vec<(Vec<f64>, Vec<f64>)>,
    /// Each storey's NRMSE by the identified loop.
    model: Vec<f64>,
    /// Each storey's by the black box, where it has one.
    black_box: Vec<f64>,
}

/// [`StoreyFits`] of record `r` against the loop's run `sink` and the black boxes on the
/// command's acceleration `a_ref`, through `band`; `None` when a storey cannot be filtered.
fn storey_fits(
    ctx: &Judge<'_>,
    r: &SystemRecord,
    sink: &Collect,
    band: &dyn Fn(&[f64]) -> Option<Vec<f64>>,
    a_ref: &[f64],
) -> Option<StoreyFits> {
    let mut storeys = Vec::new();
    let mut storey_model = Vec::new();
    let mut storey_box = Vec::new();
    for (k, st) in r.storey_a_m_s2.iter().enumerate() {
        let (Some(rec_s), Some(pred_s)) = (band(st), sink.storeys.get(k).and_then(|p| band(p)))
        else {
            return None;
        };
        storey_model.push(nrmse(&rec_s, &pred_s));
        if let Some(b) = ctx.boxes.get(k + 1).and_then(Option::as_ref) {
            if let Some(bs) = band(&b.predict(a_ref)) {
                storey_box.push(nrmse(&rec_s, &bs));
            }
        }
        storeys.push((rec_s, pred_s));
    }
    Some(StoreyFits {
        storeys,
        model: storey_model,
        black_box: storey_box,
    })
}

/// The medians over the records held out of the fit, if any.
fn medians(predictions: &[Prediction]) -> Option<HeldOutMedians> {
    let held: Vec<&Prediction> = predictions.iter().filter(|p| !p.fitted).collect();
    (!held.is_empty()).then(|| {
        let m = |f: &dyn Fn(&Prediction) -> Option<f64>| {
            let v: Vec<f64> = held.iter().filter_map(|p| f(p)).collect();
            (!v.is_empty()).then(|| median(v))
        };
        let model = m(&|p| Some(p.model.acceleration_nrmse)).unwrap_or(f64::NAN);
        let black = m(&|p| p.black_box.as_ref().map(|b| b.acceleration_nrmse));
        HeldOutMedians {
            records: held.len(),
            model_acceleration_nrmse: model,
            black_box_acceleration_nrmse: black,
            perfect_tracking_acceleration_nrmse: m(&|p| {
                Some(p.perfect_tracking.acceleration_nrmse)
            })
            .unwrap_or(f64::NAN),
            model_displacement_nrmse: m(&|p| p.model.displacement_nrmse).unwrap_or(f64::NAN),
            perfect_tracking_displacement_nrmse: m(&|p| p.perfect_tracking.displacement_nrmse)
                .unwrap_or(f64::NAN),
            model_beats_black_box: black.map(|b| model <= b),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An exact FIR system is recovered: `y[i] = 0.5·x[i] − 0.25·x[i−2] + 0.1·x[i−3]` on a
    /// pseudo-random input, fitted with 6 taps over two records.
    #[test]
    fn an_exact_fir_system_is_recovered() {
        let mut state = 7u64;
        let mut rnd = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((state >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        let truth = [0.5, 0.0, -0.25, 0.1];
        let make = |x: &[f64]| -> Vec<f64> {
            (0..x.len())
                .map(|i| {
                    truth
                        .iter()
                        .enumerate()
                        .filter(|(k, _)| *k <= i)
                        .map(|(k, h)| h * x[i - k])
                        .sum()
                })
                .collect()
        };
        let x1: Vec<f64> = (0..500).map(|_| rnd()).collect();
        let x2: Vec<f64> = (0..300).map(|_| rnd()).collect();
        let (y1, y2) = (make(&x1), make(&x2));
        let b = fir_black_box(&[&x1, &x2], &[&y1, &y2], 6).unwrap();
        for (k, h) in b.taps.iter().enumerate() {
            let t = truth.get(k).copied().unwrap_or(0.0);
            assert!((h - t).abs() < 1e-6, "tap {k}: {h} against {t}");
        }
        let p = b.predict(&x2);
        assert!(nrmse(&y2, &p) < 1e-6);
    }

    #[test]
    fn median_of_odd_and_even() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 2.0, 3.0]), 2.5);
        assert!(median(vec![]).is_nan());
    }
}
