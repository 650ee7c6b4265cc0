//! Can the table run the target, what limits it, and the largest scale that fits
//! ([`feasibility`], [`max_scale`]).
//!
//! # What is checked
//!
//! The scenario's closed loop (its model, `table_system` and specimen) is run with the
//! target's displacement command ([`crate::TargetMotion`], iteration 0: what the table does
//! before any drive iteration), and the run's peaks are held against:
//!
//! | limit | peak | allowed | ratio |
//! |---|---|---|---|
//! | `stroke_m` | signed peak displacement | the scenario's stroke | `|peak|/allowed` |
//! | `velocity_m_s` | signed peak velocity | the velocity limit | `|peak|/allowed` |
//! | `acceleration_m_s2` | signed peak acceleration | the acceleration limit | `|peak|/allowed` |
//! | `force_n` | signed peak actuator force (specimen's base shear included) | the force limit | `|peak|/allowed` |
//! | `valve_flow_m3_s` | signed peak valve flow into the cap side | the valves' flow at full opening with the null drop on each land ([`platen_system::Capacities::valve_flow_m3_s`]) | `|peak|/allowed` |
//! | `supply_pressure_pa` (accumulator only) | lowest supply pressure | the precharge (an empty bank) | drawdown `(P_set − P_min)/(P_set − P_precharge)` |
//!
//! A limit **fails** when its ratio exceeds 1. The target is `feasible` when none fails;
//! `limiting` lists those that fail, worst first, with the time of their peak. The first four
//! are the scenario's `limits` (the preset's, with the scenario's laid over them), reported as
//! `simulate` reports them ([`platen_scenario::LimitsSummary`]).
//!
//! The valve-flow "capacity" is the rated flow scaled to the null pressure drop: a flow above
//! it needs a land drop above half the supply, i.e. a load that helps the motion, so a ratio
//! near 1 means the valves are (nearly) fully open; the run itself already includes the
//! valves' saturation (its drive is clamped at ±1), so a saturated target also shows as a
//! tracking error.
//!
//! # The largest scale that fits
//!
//! [`max_scale`] scales the target's command by `s` (the baseline treatment is linear, so
//! this is the scaled target's command) and decides *fits* on the **simulated** closed loop
//! (not on a linear extrapolation of the peaks: friction, the orifice law, saturation and the
//! supply are not linear). It starts from the linear estimate `s₀ = 1/max ratio`, brackets
//! the answer between a scale that fits and one that does not (growing the bracket by 1.5×
//! until it holds), then bisects until the bracket is 0.1 % wide ([`MaxScaleSettings`]). It
//! reports the lower end (a scale verified to fit) and the bracket. The search is bounded to
//! `[`[`MaxScaleSettings::min_scale`]`, `[`MaxScaleSettings::max_scale`]`]` (default 10⁻³ to
//! 100): a target that fits at the upper bound is reported `at_upper_bound`, one that fails
//! at the lower bound has `max_scale` 0. Bisection assumes that a larger scale never fits
//! better; a run that fails numerically counts as not fitting.

use platen_integrate::Peak;
use platen_scenario::{LimitCheck, LimitsSummary};
use platen_system::Supply;
use serde::Serialize;

use crate::baseline::TargetMotion;
use crate::error::{check_setting, Result};
use crate::platen_loop::{Achieved, PlatenLoop};

/// One limit against a run's peak.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct LimitUse {
    /// The limit's name (`stroke_m`, `velocity_m_s`, `acceleration_m_s2`, `force_n`,
    /// `valve_flow_m3_s`, `supply_pressure_pa`).
    pub limit: &'static str,
    /// The run's signed peak (the lowest pressure for `supply_pressure_pa`), SI units.
    pub peak: f64,
    /// The allowed value, SI units.
    pub allowed: f64,
    /// How much of the limit the run uses: above 1 it fails.
    pub ratio: f64,
    /// When the peak occurred, s.
    pub t_s: f64,
}

impl LimitUse {
    /// Whether the limit is respected (`ratio ≤ 1`).
    pub fn respected(&self) -> bool {
        self.ratio <= 1.0
    }
}

/// Every limit of `table` against its run `achieved` (see the [module
/// documentation](self)), in a fixed order.
pub fn limit_uses(table: &PlatenLoop, achieved: &Achieved) -> Vec<LimitUse> {
    let p = &achieved.output.peaks;
    let l = &table.rig().limits;
    let plain = |limit, peak: Peak, allowed: f64| LimitUse {
        limit,
        peak: peak.value,
        allowed,
        ratio: peak.value.abs() / allowed,
        t_s: peak.t_s,
    };
    let mut uses = vec![
        plain("stroke_m", p.u_m, l.stroke_m),
        plain("velocity_m_s", p.v_m_s, l.velocity_m_s),
        plain("acceleration_m_s2", p.a_m_s2, l.acceleration_m_s2),
        plain("force_n", p.force_n, l.force_n),
    ];
    let system = table.system();
    let capacity = system.capacities().valve_flow_m3_s;
    uses.push(plain("valve_flow_m3_s", achieved.flow_peak, capacity));
    if let Supply::Accumulator(acc) = system.supply() {
        let set = system.supply_pressure_pa();
        let min = achieved.min_supply_pressure;
        uses.push(LimitUse {
            limit: "supply_pressure_pa",
            peak: min.value,
            allowed: acc.precharge_pressure_pa,
            ratio: ((set - min.value) / (set - acc.precharge_pressure_pa)).max(0.0),
            t_s: min.t_s,
        });
    }
    uses
}

/// The rig's four table limits against a run of `table`, as `simulate` reports them.
pub fn limits_summary(table: &PlatenLoop, achieved: &Achieved) -> LimitsSummary {
    let p = &achieved.output.peaks;
    let l = &table.rig().limits;
    let check = |peak: f64, limit: f64| LimitCheck {
        limit,
        peak,
        respected: peak.abs() <= limit,
    };
    LimitsSummary {
        stroke_m: check(p.u_m.value, l.stroke_m),
        velocity_m_s: check(p.v_m_s.value, l.velocity_m_s),
        acceleration_m_s2: check(p.a_m_s2.value, l.acceleration_m_s2),
        force_n: check(p.force_n.value, l.force_n),
    }
}

/// The limits that fail, worst first (ties keep the fixed order).
pub fn failing(uses: &[LimitUse]) -> Vec<LimitUse> {
    let mut f: Vec<LimitUse> = uses.iter().copied().filter(|u| !u.respected()).collect();
    f.sort_by(|a, b| b.ratio.total_cmp(&a.ratio));
    f
}

/// How [`max_scale`] searches.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MaxScaleSettings {
    /// The bracket's final relative width (default 10⁻³: 0.1 %).
    pub relative_tolerance: f64,
    /// The smallest scale tried (default 10⁻³).
    pub min_scale: f64,
    /// The largest scale tried (default 100).
    pub max_scale: f64,
}

impl Default for MaxScaleSettings {
    fn default() -> Self {
        Self {
            relative_tolerance: 1e-3,
            min_scale: 1e-3,
            max_scale: 100.0,
        }
    }
}

/// The largest scale of the target that fits every limit.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MaxScale {
    /// The largest scale verified to fit (the bracket's lower end; 0 if even
    /// [`MaxScaleSettings::min_scale`] fails).
    pub scale: f64,
    /// The final bracket `[fits, fails]` (the upper end is the bound when `at_upper_bound`).
    pub bracket: [f64; 2],
    /// Whether the target still fits at [`MaxScaleSettings::max_scale`].
    pub at_upper_bound: bool,
    /// The linear estimate `1/max ratio` from the unscaled run.
    pub linear_estimate: f64,
    /// The limits that fail at the bracket's upper end, worst first.
    pub limiting: Vec<String>,
    /// Closed-loop runs spent.
    pub runs: usize,
}

/// The feasibility of a target on a table.
#[derive(Debug, Clone, PartialEq)]
pub struct Feasibility {
    /// Whether every limit is respected.
    pub feasible: bool,
    /// Every limit against the run, in a fixed order.
    pub uses: Vec<LimitUse>,
    /// The limits that fail, worst first.
    pub limiting: Vec<LimitUse>,
    /// The scenario's four limits, as `simulate` reports them.
    pub limits: LimitsSummary,
    /// The run of the target's command (up to the end of the actuators, when it gets there:
    /// [`Achieved::end_stop`]).
    pub achieved: Achieved,
    /// The largest scale that fits (absent when not asked for).
    pub max_scale: Option<MaxScale>,
}

/// Runs the target's command on `table` and checks every limit; with `search`, finds the
/// largest scale that fits ([`max_scale`]). An infeasible target is an answer (`feasible`
/// false), not an error.
///
/// # Errors
/// [`crate::PlanError::Run`] if the unscaled run fails; a bad [`MaxScaleSettings`].
pub fn feasibility(
    table: &PlatenLoop<'_>,
    motion: &TargetMotion,
    search: Option<&MaxScaleSettings>,
) -> Result<Feasibility> {
    let achieved = table.run_or_end_stop(&motion.t_s, &motion.u_m, "the target's command")?;
    let uses = limit_uses(table, &achieved);
    let limiting = failing(&uses);
    let max_scale = match search {
        Some(settings) => Some(max_scale_from(table, motion, settings, &uses)?),
        None => None,
    };
    Ok(Feasibility {
        feasible: limiting.is_empty(),
        limits: limits_summary(table, &achieved),
        uses,
        limiting,
        achieved,
        max_scale,
    })
}

/// The largest scale of the target's command that fits every limit on the simulated closed
/// loop (see the [module documentation](self)).
///
/// # Errors
/// [`crate::PlanError::Setting`] for a tolerance outside `(0, 0.5]` or bounds that are not
/// `0 < min_scale < 1 < max_scale`; [`crate::PlanError::Run`] if the unscaled run fails.
pub fn max_scale(
    table: &PlatenLoop<'_>,
    motion: &TargetMotion,
    settings: &MaxScaleSettings,
) -> Result<MaxScale> {
    let achieved = table.run_or_end_stop(&motion.t_s, &motion.u_m, "the target's command")?;
    let uses = limit_uses(table, &achieved);
    let mut found = max_scale_from(table, motion, settings, &uses)?;
    found.runs += 1;
    Ok(found)
}

fn max_scale_from(
    table: &PlatenLoop<'_>,
    motion: &TargetMotion,
    settings: &MaxScaleSettings,
    unscaled: &[LimitUse],
) -> Result<MaxScale> {
    let worst = unscaled.iter().map(|u| u.ratio).fold(0.0, f64::max);
    let unscaled_failing: Vec<String> = failing(unscaled)
        .iter()
        .map(|u| u.limit.to_owned())
        .collect();
    search_max_scale(settings, worst, unscaled_failing, &mut |s| {
        let u: Vec<f64> = motion.u_m.iter().map(|x| x * s).collect();
        match table.run_or_end_stop(&motion.t_s, &u, "a scaled command") {
            Ok(a) => failing(&limit_uses(table, &a))
                .iter()
                .map(|u| u.limit.to_owned())
                .collect(),
            Err(_) => vec!["run_failed".to_owned()],
        }
    })
}

/// The search of [`max_scale`] on any plant: `failing_at(s)` runs the command scaled by `s`
/// and names the limits that fail (none: it fits; `run_failed` for a run that failed);
/// `worst` is the unscaled run's largest ratio and `unscaled_failing` what fails unscaled
/// (see the [module documentation](self)). Returns the answer with the runs spent here.
///
/// # Errors
/// [`crate::PlanError::Setting`] for bad [`MaxScaleSettings`].
pub fn search_max_scale(
    settings: &MaxScaleSettings,
    worst: f64,
    unscaled_failing: Vec<String>,
    failing_at: &mut dyn FnMut(f64) -> Vec<String>,
) -> Result<MaxScale> {
    let (tol, lo_bound, hi_bound) = checked(settings)?;
    let unscaled_fits = unscaled_failing.is_empty();
    let linear_estimate = if worst > 0.0 { 1.0 / worst } else { hi_bound };
    let start = linear_estimate.clamp(lo_bound, hi_bound);
    let mut search = Search {
        failing_at,
        bounds: (lo_bound, hi_bound),
        linear_estimate,
        lo: f64::NAN,
        hi: f64::NAN,
        hi_failing: Vec::new(),
        runs: 0,
    };
    // The bracket [lo (fits), hi (fails)], from the unscaled run and the linear estimate.
    if unscaled_fits {
        search.lo = 1.0;
    } else {
        search.hi = 1.0;
        search.hi_failing = unscaled_failing;
    }
    search.around(start);
    if let Some(found) = search.grow() {
        return Ok(found);
    }
    search.bisect(tol);
    Ok(search.found(false))
}

/// The search's relative tolerance and its bounds `[min_scale, max_scale]`, checked.
fn checked(settings: &MaxScaleSettings) -> Result<(f64, f64, f64)> {
    let tol = check_setting(
        "relative_tolerance",
        settings.relative_tolerance,
        settings.relative_tolerance > 0.0 && settings.relative_tolerance <= 0.5,
        "a relative width in (0, 0.5]",
    )?;
    let lo_bound = check_setting(
        "min_scale",
        settings.min_scale,
        settings.min_scale > 0.0 && settings.min_scale < 1.0,
        "a scale in (0, 1)",
    )?;
    let hi_bound = check_setting(
        "max_scale",
        settings.max_scale,
        settings.max_scale > 1.0,
        "a finite scale > 1",
    )?;
    Ok((tol, lo_bound, hi_bound))
}

/// The state of [`max_scale_from`]'s search: the bracket `[lo (fits), hi (fails)]` (NaN
/// while an end is not known), what fails at `hi`, and the closed-loop runs spent.
struct Search<'f> {
    /// The limits that fail at a scale.
    failing_at: &'f mut dyn FnMut(f64) -> Vec<String>,
    /// `[min_scale, max_scale]`.
    bounds: (f64, f64),
    linear_estimate: f64,
    lo: f64,
    hi: f64,
    hi_failing: Vec<String>,
    runs: usize,
}

impl Search<'_> {
    /// Whether the command scaled by `s` fits, and what fails.
    fn fits(&mut self, s: f64) -> (bool, Vec<String>) {
        self.runs += 1;
        let f = (self.failing_at)(s);
        (f.is_empty(), f)
    }

    /// Runs `s` and makes it the lower end if it fits, else the upper end.
    fn bisect_at(&mut self, s: f64) -> bool {
        let (ok, f) = self.fits(s);
        if ok {
            self.lo = s;
        } else {
            self.hi = s;
            self.hi_failing = f;
        }
        ok
    }

    /// Tries 2 % either side of `start` (the linear estimate within the bounds), where they
    /// narrow the bracket.
    fn around(&mut self, start: f64) {
        let (lo_bound, hi_bound) = self.bounds;
        let (below, above) = (start * (1.0 - 0.02), start * (1.0 + 0.02));
        if self.lo.is_nan() || self.lo < below {
            let s = below.clamp(lo_bound, hi_bound);
            let (ok, f) = self.fits(s);
            if ok {
                self.lo = s;
            } else if self.hi.is_nan() || s < self.hi {
                self.hi = s;
                self.hi_failing = f;
            }
        }
        if self.hi.is_nan() || self.hi > above {
            let s = above.clamp(lo_bound, hi_bound);
            if self.lo.is_nan() || s > self.lo {
                let (ok, f) = self.fits(s);
                if ok {
                    self.lo = self.lo.max(s);
                } else {
                    self.hi = s;
                    self.hi_failing = f;
                }
            }
        }
    }

    /// Grows the bracket by 1.5× until it holds, within the bounds; the answer when a bound
    /// is reached (nothing fits at the lower bound, everything at the upper).
    fn grow(&mut self) -> Option<MaxScale> {
        let (lo_bound, hi_bound) = self.bounds;
        while self.lo.is_nan() {
            let s = (self.hi / 1.5).max(lo_bound);
            if !self.bisect_at(s) && s <= lo_bound {
                return Some(MaxScale {
                    scale: 0.0,
                    bracket: [0.0, lo_bound],
                    ..self.found(false)
                });
            }
        }
        while self.hi.is_nan() {
            let s = (self.lo * 1.5).min(hi_bound);
            if self.bisect_at(s) && s >= hi_bound {
                return Some(MaxScale {
                    scale: hi_bound,
                    bracket: [hi_bound, hi_bound],
                    limiting: Vec::new(),
                    ..self.found(true)
                });
            }
        }
        None
    }

    /// Bisects until the bracket is at most `tol` of its lower end wide.
    fn bisect(&mut self, tol: f64) {
        while (self.hi - self.lo) > tol * self.lo {
            self.bisect_at(0.5 * (self.lo + self.hi));
        }
    }

    /// The answer: the lower end, the bracket and what fails at its upper end.
    fn found(&self, at_upper_bound: bool) -> MaxScale {
        MaxScale {
            scale: self.lo,
            bracket: [self.lo, self.hi],
            at_upper_bound,
            linear_estimate: self.linear_estimate,
            limiting: self.hi_failing.clone(),
            runs: self.runs,
        }
    }
}
