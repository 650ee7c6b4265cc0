//! The discrete controller: one update per controller sample, held until the next.

use crate::params::Controller;

/// What the controller reads at a sample: the command and its derivatives, the feedback.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ControllerInput {
    /// Command displacement `u_ref`, m.
    pub command_u_m: f64,
    /// Command velocity `v_ref`, m/s.
    pub command_v_m_s: f64,
    /// Command acceleration `a_ref`, m/s².
    pub command_a_m_s2: f64,
    /// Platen displacement, m.
    pub u_m: f64,
    /// Platen velocity, m/s.
    pub v_m_s: f64,
    /// Platen acceleration, m/s².
    pub a_m_s2: f64,
    /// Pressure difference `p_a − p_b`, Pa.
    pub delta_p_pa: f64,
}

/// The controller's memory between samples.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ControllerState {
    /// The last `Δp` the high-pass filter read, Pa (`None` before the first sample).
    last_delta_p_pa: Option<f64>,
    /// The high-pass filter's output, Pa.
    highpassed_pa: f64,
    /// The integrator's contribution to the drive.
    integral: f64,
    /// The drive held since the last sample.
    pub drive: f64,
    /// Whether the last drive was saturated.
    pub saturated: bool,
}

impl Controller {
    /// The sample period, s.
    pub fn period_s(&self) -> f64 {
        1.0 / self.sample_rate_hz
    }

    /// One controller sample: updates `state` from `input` and returns the new drive
    /// (`|d| ≤ 1`). The first sample starts the high-pass filter at its input (output 0).
    pub fn update(&self, state: &mut ControllerState, input: &ControllerInput) -> f64 {
        let t = self.period_s();
        let dp = input.delta_p_pa;
        state.highpassed_pa = match (state.last_delta_p_pa, self.delta_p_highpass_hz > 0.0) {
            (_, false) => dp,
            (None, true) => 0.0,
            (Some(prev), true) => {
                // Tustin of s/(s + ω): y_k·(2/T + ω) = (2/T)(x_k − x_{k−1}) + (2/T − ω)·y_{k−1}.
                let w = std::f64::consts::TAU * self.delta_p_highpass_hz;
                let c = 2.0 / t;
                (c * (dp - prev) + (c - w) * state.highpassed_pa) / (c + w)
            }
        };
        state.last_delta_p_pa = Some(dp);
        let error = input.command_u_m - input.u_m;
        let raw = self.displacement_gain_per_m * error
            + self.velocity_feedforward_s_per_m * input.command_v_m_s
            + self.acceleration_feedforward_s2_per_m * input.command_a_m_s2
            - self.velocity_feedback_s_per_m * input.v_m_s
            - self.acceleration_feedback_s2_per_m * input.a_m_s2
            - self.delta_p_gain_per_pa * state.highpassed_pa;
        let step = self.integral_gain_per_m_s * error * t;
        let candidate = raw + state.integral + step;
        // No wind-up: the integrator holds while the drive is saturated its way.
        if candidate.abs() <= 1.0 || candidate.signum() != step.signum() {
            state.integral += step;
        }
        let d = raw + state.integral;
        state.saturated = d.abs() > 1.0;
        state.drive = d.clamp(-1.0, 1.0);
        state.drive
    }
}
