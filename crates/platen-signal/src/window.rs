//! Tapering windows for FIR design and spectral estimation.

use std::f64::consts::PI;

/// A tapering window of the generalised-cosine family
/// `w(x) = a₀ − a₁·cos(2πx) + a₂·cos(4πx)`, `x ∈ [0, 1]`.
///
/// | window | first side lobe | transition width of a windowed-sinc FIR of order `M` |
/// |---|---|---|
/// | [`Window::Rectangular`] | −13 dB | ≈ 0.9·f_s/M (stop band only −21 dB) |
/// | [`Window::Hann`] | −31 dB | ≈ 3.1·f_s/M (stop band −44 dB) |
/// | [`Window::Hamming`] (default) | −43 dB | ≈ 3.3·f_s/M (stop band −53 dB) |
/// | [`Window::Blackman`] | −58 dB | ≈ 5.5·f_s/M (stop band −74 dB) |
#[non_exhaustive]
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Window {
    /// No taper (`w = 1`).
    Rectangular,
    /// Hann: `0.5 − 0.5·cos(2πx)`.
    Hann,
    /// Hamming: `0.54 − 0.46·cos(2πx)` (the default for FIR design).
    #[default]
    Hamming,
    /// Blackman: `0.42 − 0.5·cos(2πx) + 0.08·cos(4πx)`.
    Blackman,
}

impl Window {
    fn coefficients(self) -> [f64; 3] {
        match self {
            Window::Rectangular => [1.0, 0.0, 0.0],
            Window::Hann => [0.5, 0.5, 0.0],
            Window::Hamming => [0.54, 0.46, 0.0],
            Window::Blackman => [0.42, 0.5, 0.08],
        }
    }

    fn value(self, x: f64) -> f64 {
        let [a0, a1, a2] = self.coefficients();
        a0 - a1 * (2.0 * PI * x).cos() + a2 * (4.0 * PI * x).cos()
    }

    /// The symmetric window of `len` samples (`x = k/(len − 1)`), used to design linear-phase
    /// FIR filters. `len = 1` gives `[1.0]`; `len = 0` gives an empty vector.
    pub fn symmetric(self, len: usize) -> Vec<f64> {
        match len {
            0 => Vec::new(),
            1 => vec![1.0],
            _ => {
                // Computed on one half and mirrored, so the window is exactly symmetric.
                let d = (len - 1) as f64;
                let mut w = vec![0.0; len];
                for k in 0..len.div_ceil(2) {
                    let v = self.value(k as f64 / d);
                    w[k] = v;
                    w[len - 1 - k] = v;
                }
                w
            }
        }
    }

    /// The periodic window of `len` samples (`x = k/len`; the symmetric window of `len + 1`
    /// samples without its last sample), used for spectral estimation as SciPy does.
    pub fn periodic(self, len: usize) -> Vec<f64> {
        let d = len as f64;
        (0..len).map(|k| self.value(k as f64 / d)).collect()
    }
}
