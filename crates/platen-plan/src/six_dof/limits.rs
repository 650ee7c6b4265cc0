//! The limits of a multi-axis table against a run ([`limit_uses`], [`TableLimitUse`]) and
//! the feasibility of a target ([`TableFeasibility`]).

use std::collections::BTreeMap;

use serde::Serialize;

use platen_integrate::TableRun;
use platen_scenario::multi_axis::{
    TableScenario, ACCELERATION_COLUMNS, POSE_COLUMNS, RATE_COLUMNS,
};

use crate::feasibility::MaxScale;

/// The share of a single-acting actuator's static force below which it counts as lifted off
/// (`{name}.uplift`): 1 %.
pub const UPLIFT_RESIDUAL: f64 = 0.01;

/// One limit of a multi-axis table against a run's peak.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TableLimitUse {
    /// The limit: `x.stroke_m`, `z.acceleration_m_s2`, `v3.force_n`, `h1.flow_m3_s`,
    /// `overturning_moment_n_m`, …
    pub limit: String,
    /// The run's signed peak, SI units.
    pub peak: f64,
    /// The allowed value (the bound on the peak's side), SI units.
    pub allowed: f64,
    /// How much of the limit the run uses: above 1 it fails.
    pub ratio: f64,
    /// When the peak occurred, s.
    pub t_s: f64,
    /// When the limit was first exceeded, s (`null` when it was not).
    pub first_exceeded_s: Option<f64>,
}

impl TableLimitUse {
    /// Whether the limit is respected (`ratio ≤ 1`).
    pub fn respected(&self) -> bool {
        self.ratio <= 1.0
    }
}

/// The use of a two-sided limit `[lower ≤ 0, upper ≥ 0]` by `x` at the times `t`.
pub(super) fn use_of(limit: String, t: &[f64], x: &[f64], lower: f64, upper: f64) -> TableLimitUse {
    let ratio_of = |v: f64| {
        if v >= 0.0 {
            if upper > 0.0 {
                v / upper
            } else if v > 0.0 {
                f64::INFINITY
            } else {
                0.0
            }
        } else if lower < 0.0 {
            v / lower
        } else {
            f64::INFINITY
        }
    };
    let mut worst = (0.0_f64, 0.0, t.first().copied().unwrap_or(0.0));
    let mut first = None;
    for (&ti, &v) in t.iter().zip(x) {
        let r = ratio_of(v);
        if r > worst.0 {
            worst = (r, v, ti);
        }
        if r > 1.0 && first.is_none() {
            first = Some(ti);
        }
    }
    let (ratio, peak, t_s) = worst;
    TableLimitUse {
        limit,
        peak,
        allowed: if peak >= 0.0 { upper } else { lower },
        ratio,
        t_s,
        first_exceeded_s: first,
    }
}

/// Every limit of the scenario's table against the run `r` (see the [module
/// documentation](super)), in a fixed order: the axes' (x … yaw, where `table.limits` gives
/// them), the actuators' (in the table's order), the overturning moment.
pub fn limit_uses(scenario: &TableScenario, r: &TableRun) -> Vec<TableLimitUse> {
    let mut uses = axis_uses(scenario, r);
    uses.extend(actuator_uses(scenario, r));
    let t = r.column("t_s").unwrap_or(&[]);
    if let (Some(limit), Some(mx), Some(my)) = (
        scenario.limits.overturning_moment_n_m,
        r.column("overturning_moment_x_n_m"),
        r.column("overturning_moment_y_n_m"),
    ) {
        let m: Vec<f64> = mx.iter().zip(my).map(|(a, b)| a.hypot(*b)).collect();
        uses.push(use_of(
            "overturning_moment_n_m".to_owned(),
            t,
            &m,
            -limit,
            limit,
        ));
    }
    uses
}

/// The axes' limits (x … yaw, where `table.limits` gives them) against the run `r`.
fn axis_uses(scenario: &TableScenario, r: &TableRun) -> Vec<TableLimitUse> {
    let col = |name: &str| r.column(name).unwrap_or(&[]);
    let t = col("t_s");
    let mut uses = Vec::new();
    let names = ["x", "y", "z", "roll", "pitch", "yaw"];
    for (k, limits) in scenario.limits.each().iter().enumerate() {
        let kinds: [(&str, &str); 3] = if k < 3 {
            [
                ("stroke_m", POSE_COLUMNS[k]),
                ("velocity_m_s", RATE_COLUMNS[k]),
                ("acceleration_m_s2", ACCELERATION_COLUMNS[k]),
            ]
        } else {
            [
                ("angle_rad", POSE_COLUMNS[k]),
                ("rate_rad_s", RATE_COLUMNS[k]),
                ("acceleration_rad_s2", ACCELERATION_COLUMNS[k]),
            ]
        };
        for (limit, (what, column)) in limits.iter().zip(kinds) {
            if let Some(l) = limit {
                uses.push(use_of(
                    format!("{}.{what}", names[k]),
                    t,
                    col(column),
                    -l,
                    *l,
                ));
            }
        }
    }
    uses
}

/// Each actuator's limits (stroke, force, uplift of a single-acting one, flow), in the
/// table's order, against the run `r`.
fn actuator_uses(scenario: &TableScenario, r: &TableRun) -> Vec<TableLimitUse> {
    let col = |name: &str| r.column(name).unwrap_or(&[]);
    let t = col("t_s");
    let mut uses = Vec::new();
    let capacities = scenario.flow_capacities_m3_s();
    for (i, (a, (pull, push))) in scenario
        .table
        .actuators()
        .iter()
        .zip(scenario.force_limits_n())
        .enumerate()
    {
        let name = &a.name;
        uses.push(use_of(
            format!("{name}.stroke_m"),
            t,
            col(&format!("{name}_stroke_m")),
            -a.stroke_m,
            a.stroke_m,
        ));
        let force = col(&format!("{name}_force_n"));
        uses.push(use_of(format!("{name}.force_n"), t, force, pull, push));
        if a.rod_side_area_m2 == 0.0 && force.first().is_some_and(|&f0| f0 > 0.0) {
            uses.push(uplift_use(name, t, force));
        }
        if let (Some(c), Some(flow)) = (&capacities, r.column(&format!("{name}_flow_m3_s"))) {
            uses.push(use_of(format!("{name}.flow_m3_s"), t, flow, -c[i], c[i]));
        }
    }
    uses
}

/// The uplift of the single-acting actuator `name` whose force at the times `t` is `force`
/// (its first sample positive): its share of the static hold is its preload; losing it all
/// (below [`UPLIFT_RESIDUAL`] of it) the chamber nears the cavitation floor and the actuator
/// no longer holds the platen down.
fn uplift_use(name: &str, t: &[f64], force: &[f64]) -> TableLimitUse {
    let f0 = force[0];
    let mut u = use_of(
        format!("{name}.uplift"),
        t,
        &force.iter().map(|f| f0 - f).collect::<Vec<_>>(),
        f64::NEG_INFINITY,
        (1.0 - UPLIFT_RESIDUAL) * f0,
    );
    u.peak = f0 - u.peak;
    u.allowed = UPLIFT_RESIDUAL * f0;
    u
}

/// The limits that fail, worst first.
pub(crate) fn failing(uses: &[TableLimitUse]) -> Vec<TableLimitUse> {
    let mut f: Vec<TableLimitUse> = uses.iter().filter(|u| !u.respected()).cloned().collect();
    f.sort_by(|a, b| b.ratio.total_cmp(&a.ratio));
    f
}

/// The feasibility of a target on a multi-axis table.
#[derive(Debug, Clone, Serialize)]
pub struct TableFeasibility {
    /// Whether every limit is respected.
    pub feasible: bool,
    /// The limits that fail, worst first.
    pub limiting: Vec<TableLimitUse>,
    /// The failing limit exceeded first, with when (`null` when feasible).
    pub binds_first: Option<TableLimitUse>,
    /// Every limit against the run of the target's own commands.
    pub uses: Vec<TableLimitUse>,
    /// The largest common scale that fits (`null` when not asked for).
    pub max_scale: Option<MaxScale>,
    /// The largest scale of each axis given, the others as given (empty when not asked for).
    pub per_axis_max_scale: BTreeMap<&'static str, MaxScale>,
}
