//! Continuous-discrete state-augmented extended Kalman filter (SAEKF) that identifies the four
//! linear hull coefficients of a sway-yaw model on-line.
//!
//! # Source
//! The DDG-51 thesis [Taylor2000]:
//! * [Taylor2000, sec. 2.2, Table 2.1] (after Gelb (1974), Table 6.1-1): propagation dx̂/dt = f(x̂),
//!   Ṗ = F P + P Fᵀ + Q [Taylor2000, eqs. (2.10)-(2.12)], gain K = P⁻Hᵀ(HP⁻Hᵀ + R)⁻¹
//!   [Taylor2000, eq. (2.20)], update x̂⁺ = x̂⁻ + K(z − Hx̂⁻) [Taylor2000, eq. (2.19)],
//!   P⁺ = (I − KH)P⁻ [Taylor2000, eq. (2.21)]; state augmentation with ṗ = 0
//!   [Taylor2000, App. A, eqs. (A.1)-(A.2)];
//! * the DDG-51 filter [Taylor2000, sec. 4.2-4.3]: state X = [u, v, r, n, p₁, p₂, p₃, p₄] with
//!   p₁ = −Y′_v, p₂ = m′ − Y′_r, p₃ = −N′_v, p₄ = m′x′_G − N′_r; u̇ = ṅ = 0 ("filter model was
//!   linear", [Taylor2000, sec. 4.3.2]); u, v, r, n measured, H = [I₄ 0]; the Jacobian entries
//!   (derived here);
//! * M ν̇′ = f, f₂ = −p₁v′ − p₂r′ + Y_R, f₃ = −p₃v′ − p₄r′ + N_R with u′ = 1
//!   [Taylor2000, sec. 4.1, eqs. (4.1)-(4.2)];
//! * [Taylor2000, Table 4.1]: Q = 0.05 on the physical states, "fake" noise FQ = 0.01 on the
//!   parameters, R = 0.01; Esso Osaka run Q = 0 [Taylor2000, sec. 2.3];
//! * the parameter value is the mean of the last 67 % of the estimates [Taylor2000, sec. 4.3.3].
//!
//! # Model (prime system, time t′ = tU/L)
//! ```text
//! u̇′ = 0,  ṅ′ = 0,  ṗᵢ = 0
//! [v̇′, ṙ′]ᵀ = M⁻¹ ( b δ − N(p) [v′, r′]ᵀ ),   N(p) = [[p₁, p₂], [p₃, p₄]],  b = [Y′_δ, N′_δ]
//! z = [u/U, v/U, rL/U, n/n₀]  (H = [I₄ 0])
//! ```
//! M (mass and added mass) and b (rudder) are known parameters: the thesis says the rudder
//! force "is assumed to be accurately modeled and requires no identification"
//! [Taylor2000, sec. 4.1].
//!
//! # Readings taken (the thesis is silent on these)
//! * Q and FQ are continuous spectral densities per unit of nondimensional time t′; R is the
//!   variance of each nondimensional measurement per sample. All are diagonal.
//! * The rudder term is linear (b δ) — the thesis calls its filter model "completely linear"
//!   [Taylor2000, sec. 6.2] — and δ is the rudder angle actually applied (an input, held over a
//!   step).
//! * Sample interval: a parameter (default 1 s, "not less than one second",
//!   [Taylor2000, sec. 2.2.1]). At the
//!   start of a communication step that reaches the next sample time, the held measurement
//!   updates the estimate; then x̂ and P are propagated over the step (classical RK4 on x̂ and
//!   P together, sub-step ≤ `max_substep`). The outputs are therefore the a-priori estimates at
//!   the end of the step; they depend on the state only.
//! * x̂₀ and P₀ are parameters (P₀ diagonal, one variance for the physical states and one for
//!   the coefficients); u′ and n′ start at 1.
//! * The update uses the Joseph form (I − KH)P(I − KH)ᵀ + KRKᵀ, algebraically [Taylor2000, eq. (2.21)].
//! * The running mean over the last 67 % of the estimates: after the k-th update, the mean of
//!   the a-posteriori estimates k − w + 1 … k with w = max(1, round(0.67 k)). The estimate
//!   history is kept as prefix sums (32 bytes per update: 115 kB per hour at 1 s), which is
//!   what makes the window exact; it grows by doubling, so no allocation happens on most steps.

use crate::error::{
    check_finite, check_mass_matrix_2x2, check_non_negative, check_positive, require,
};
use crate::integrate::rk4_advance;
use nalgebra::{Matrix2, SMatrix, SVector, Vector2};
use serde::{Deserialize, Serialize};

type M8 = SMatrix<f64, 8, 8>;
type V8 = SVector<f64, 8>;
type M4 = SMatrix<f64, 4, 4>;
type M84 = SMatrix<f64, 8, 4>;

/// Number of propagated numbers: x̂ (8) and P (8 × 8, column-major).
const NPROP: usize = 8 + 64;

/// Filter parameters (prime-system quantities unless a unit is given).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParameterEkfParams {
    /// Reference length L [m].
    pub length: f64,
    /// Nominal speed U [m/s] (nondimensionalisation and time scale L/U).
    pub speed: f64,
    /// Nominal shaft speed n₀ [rpm] (n′ = n/n₀; the thesis leaves n′ undefined).
    pub shaft_speed: f64,
    /// Mass matrix M′ = [[m − Y_v̇, m x_G − Y_ṙ], [m x_G − N_v̇, I_z − N_ṙ]] (row-major).
    pub mass: [[f64; 2]; 2],
    /// Rudder coefficients b′ = [Y′_δ, N′_δ] per rad.
    pub rudder: [f64; 2],
    /// Initial coefficient estimates [−Y_v, m − Y_r, −N_v, m x_G − N_r].
    pub initial_coefficients: [f64; 4],
    /// P₀ diagonal of the physical states (u′, v′, r′, n′).
    pub initial_state_variance: f64,
    /// P₀ diagonal of the coefficients.
    pub initial_coefficient_variance: f64,
    /// Q, spectral density on the physical states per unit t′ ([Taylor2000, Table 4.1]: 0.05; Esso Osaka 0).
    pub process_noise: f64,
    /// FQ, "fake" spectral density on the coefficients per unit t′ ([Taylor2000, Table 4.1]: 0.01).
    pub coefficient_noise: f64,
    /// R, variance of each nondimensional measurement ([Taylor2000, Table 4.1]: 0.01).
    pub measurement_noise: f64,
    /// Measurement sample interval [s] (default 1).
    pub sample_interval: f64,
    /// Fraction of the estimate history averaged (0.67).
    pub averaging_fraction: f64,
    /// Largest RK4 sub-step of the propagation [s] (default 0.1).
    pub max_substep: f64,
}

impl ParameterEkfParams {
    /// [Taylor2000, Table 4.1] noise (Q 0.05, FQ 0.01, R 0.01) on the given ship data; P₀ = 0.01 (states),
    /// 1e-4 (coefficients, i.e. σ = 0.01, the size of −Y′_v); sample interval 1 s.
    pub fn table_4_1(
        length: f64,
        speed: f64,
        shaft_speed: f64,
        mass: [[f64; 2]; 2],
        rudder: [f64; 2],
        initial_coefficients: [f64; 4],
    ) -> Self {
        ParameterEkfParams {
            length,
            speed,
            shaft_speed,
            mass,
            rudder,
            initial_coefficients,
            initial_state_variance: 0.01,
            initial_coefficient_variance: 1e-4,
            process_noise: 0.05,
            coefficient_noise: 0.01,
            measurement_noise: 0.01,
            sample_interval: 1.0,
            averaging_fraction: 0.67,
            max_substep: 0.1,
        }
    }

    /// Checks every parameter; the message names the parameter and its value.
    pub fn validate(&self) -> Result<(), String> {
        for (n, v) in [
            ("length", self.length),
            ("speed", self.speed),
            ("shaft_speed", self.shaft_speed),
            ("measurement_noise", self.measurement_noise),
            ("sample_interval", self.sample_interval),
            ("max_substep", self.max_substep),
        ] {
            check_positive(n, v)?;
        }
        for (n, v) in [
            ("initial_state_variance", self.initial_state_variance),
            (
                "initial_coefficient_variance",
                self.initial_coefficient_variance,
            ),
            ("process_noise", self.process_noise),
            ("coefficient_noise", self.coefficient_noise),
        ] {
            check_non_negative(n, v)?;
        }
        require(
            self.averaging_fraction > 0.0 && self.averaging_fraction <= 1.0,
            "averaging_fraction",
            self.averaging_fraction,
            "must be in (0, 1]",
        )?;
        check_mass_matrix_2x2(&self.mass)?;
        for (n, v) in [("b1", self.rudder[0]), ("b2", self.rudder[1])] {
            check_finite(n, v)?;
        }
        let names = [
            "initial_neg_y_v",
            "initial_m_minus_y_r",
            "initial_neg_n_v",
            "initial_mxg_minus_n_r",
        ];
        for (n, v) in names.iter().zip(self.initial_coefficients) {
            check_finite(n, v)?;
        }
        Ok(())
    }
}

/// First-order Nomoto constants (T′, K′) of the sway-yaw model M ν̇′ + N ν′ = b δ
/// (the standard formulas, as in `hull::nomoto`): T′ = T₁ + T₂ − T₃, K′ = (n₁₁b₂ − n₂₁b₁)/det N.
pub fn nomoto_constants(m: &[[f64; 2]; 2], n: &[f64; 4], b: &[f64; 2]) -> (f64, f64) {
    let (n11, n12, n21, n22) = (n[0], n[1], n[2], n[3]);
    let det_n = n11 * n22 - n12 * n21;
    let t1t2 = (m[0][0] * n22 + m[1][1] * n11 - m[0][1] * n21 - m[1][0] * n12) / det_n;
    let k = (n11 * b[1] - n21 * b[0]) / det_n;
    let kt3 = (m[0][0] * b[1] - m[1][0] * b[0]) / det_n;
    (t1t2 - kt3 / k, k)
}

/// The filter.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ParameterEkf {
    params: ParameterEkfParams,
    /// M⁻¹ and M⁻¹ b.
    minv: Matrix2<f64>,
    minv_b: Vector2<f64>,
    /// x̂ = [u′, v′, r′, n′, p₁..p₄] and P.
    x: V8,
    p: M8,
    /// Last innovation z − Hx̂⁻ (nondimensional).
    innovation: [f64; 4],
    /// Time of the first sample and the number of updates done.
    t_start: f64,
    updates: u64,
    /// Prefix sums of the a-posteriori coefficient estimates (entry 0 = 0).
    sums: Vec<[f64; 4]>,
}

impl ParameterEkf {
    /// A filter with the given parameters; the first sample is taken at `start_time`.
    pub fn new(params: ParameterEkfParams, start_time: f64) -> Result<Self, String> {
        params.validate()?;
        let m = Matrix2::new(
            params.mass[0][0],
            params.mass[0][1],
            params.mass[1][0],
            params.mass[1][1],
        );
        let minv = m
            .try_inverse()
            .ok_or_else(|| "mass matrix is singular (m11, m12, m21, m22)".to_string())?;
        let minv_b = minv * Vector2::new(params.rudder[0], params.rudder[1]);
        let c = params.initial_coefficients;
        let x = V8::from_row_slice(&[1.0, 0.0, 0.0, 1.0, c[0], c[1], c[2], c[3]]);
        let mut p = M8::zeros();
        for i in 0..4 {
            p[(i, i)] = params.initial_state_variance;
            p[(i + 4, i + 4)] = params.initial_coefficient_variance;
        }
        let mut sums = Vec::with_capacity(4096);
        sums.push([0.0; 4]);
        Ok(ParameterEkf {
            params,
            minv,
            minv_b,
            x,
            p,
            innovation: [0.0; 4],
            t_start: start_time,
            updates: 0,
            sums,
        })
    }

    pub fn params(&self) -> &ParameterEkfParams {
        &self.params
    }

    /// x̂ = [u′, v′, r′, n′, p₁, p₂, p₃, p₄].
    pub fn estimate(&self) -> [f64; 8] {
        let mut e = [0.0; 8];
        e.copy_from_slice(self.x.as_slice());
        e
    }

    /// Error covariance P.
    pub fn covariance(&self) -> &M8 {
        &self.p
    }

    /// Current coefficient estimates [−Y_v, m − Y_r, −N_v, m x_G − N_r].
    pub fn coefficients(&self) -> [f64; 4] {
        [self.x[4], self.x[5], self.x[6], self.x[7]]
    }

    /// Estimated u [m/s], v [m/s], r [rad/s], n [rpm].
    pub fn dimensional_states(&self) -> [f64; 4] {
        let (l, u) = (self.params.length, self.params.speed);
        [
            self.x[0] * u,
            self.x[1] * u,
            self.x[2] * u / l,
            self.x[3] * self.params.shaft_speed,
        ]
    }

    /// Innovation z − Hx̂⁻ of the last update (nondimensional u′, v′, r′, n′).
    pub fn innovation(&self) -> [f64; 4] {
        self.innovation
    }

    /// Number of measurement updates so far.
    pub fn updates(&self) -> u64 {
        self.updates
    }

    /// Mean of the last `averaging_fraction` of the a-posteriori coefficient estimates (the
    /// current estimate before the first update).
    pub fn averaged_coefficients(&self) -> [f64; 4] {
        let k = self.sums.len() - 1;
        if k == 0 {
            return self.coefficients();
        }
        let w = ((self.params.averaging_fraction * k as f64).round() as usize).clamp(1, k);
        let (a, b) = (&self.sums[k - w], &self.sums[k]);
        let mut out = [0.0; 4];
        for i in 0..4 {
            out[i] = (b[i] - a[i]) / w as f64;
        }
        out
    }

    /// (T′, K′) of the model with the averaged coefficients.
    pub fn identified_nomoto(&self) -> (f64, f64) {
        nomoto_constants(
            &self.params.mass,
            &self.averaged_coefficients(),
            &self.params.rudder,
        )
    }

    /// Measurement update with u [m/s], v [m/s], r [rad/s], n [rpm] [Taylor2000, eqs. (2.19)-(2.21)].
    pub fn update(&mut self, u: f64, v: f64, r: f64, n: f64) {
        let (l, us) = (self.params.length, self.params.speed);
        let z = [u / us, v / us, r * l / us, n / self.params.shaft_speed];
        let mut nu = SVector::<f64, 4>::zeros();
        for i in 0..4 {
            nu[i] = z[i] - self.x[i];
        }
        let ph: M84 = self.p.fixed_columns::<4>(0).into_owned();
        let s: M4 = self.p.fixed_view::<4, 4>(0, 0).into_owned()
            + M4::identity() * self.params.measurement_noise;
        let Some(si) = s.try_inverse() else {
            return;
        };
        let k: M84 = ph * si;
        let dx = k * nu;
        if dx.iter().all(|v| v.is_finite()) {
            self.x += dx;
            let mut ikh = M8::identity();
            for i in 0..8 {
                for j in 0..4 {
                    ikh[(i, j)] -= k[(i, j)];
                }
            }
            let pp =
                ikh * self.p * ikh.transpose() + k * k.transpose() * self.params.measurement_noise;
            self.p = (pp + pp.transpose()) * 0.5;
        }
        self.innovation = [nu[0], nu[1], nu[2], nu[3]];
        self.updates += 1;
        let last = *self.sums.last().expect("prefix sums start with 0");
        self.sums.push([
            last[0] + self.x[4],
            last[1] + self.x[5],
            last[2] + self.x[6],
            last[3] + self.x[7],
        ]);
    }

    /// Propagates x̂ and P over `h` seconds with the rudder angle `rudder` [rad] held
    /// ([Taylor2000, eqs. (2.10)-(2.12)], RK4 in t′).
    pub fn propagate(&mut self, rudder: f64, h: f64) {
        let scale = self.params.speed / self.params.length;
        let qs = self.params.process_noise;
        let qp = self.params.coefficient_noise;
        let minv = self.minv;
        let bd = self.minv_b * rudder;
        let mut y = [0.0; NPROP];
        y[..8].copy_from_slice(self.x.as_slice());
        y[8..].copy_from_slice(self.p.as_slice());
        rk4_advance(&mut y, h * scale, self.params.max_substep * scale, |y| {
            derivative(y, &minv, &bd, qs, qp)
        });
        if y.iter().all(|v| v.is_finite()) {
            self.x.copy_from_slice(&y[..8]);
            let p = M8::from_column_slice(&y[8..]);
            self.p = (p + p.transpose()) * 0.5;
        }
    }

    /// One communication step from `t` to `t + h`: a measurement update when `t` reaches the
    /// next sample time (first at the start time), then propagation with the rudder held.
    pub fn step(&mut self, t: f64, h: f64, measured: [f64; 4], rudder: f64) {
        let ts = self.params.sample_interval;
        let next = self.t_start + self.updates as f64 * ts;
        if t >= next - 1e-9 * ts.max(1.0) {
            self.update(measured[0], measured[1], measured[2], measured[3]);
            // Skip sample times missed inside a long step (one update per step at most).
            let due = ((t - self.t_start) / ts + 1e-9).floor() as u64 + 1;
            if due > self.updates {
                self.updates = due;
            }
        }
        self.propagate(rudder, h);
    }
}

/// Filter dynamics f(x̂) (only v̇′, ṙ′ are non-zero) and its Jacobian F = ∂f/∂x (derived here,
/// with the linear rudder): rows v̇′, ṙ′ hold −M⁻¹N in the (v′, r′) columns and
/// −M⁻¹[:, 0]·(v′, r′), −M⁻¹[:, 1]·(v′, r′) in the (p₁, p₂), (p₃, p₄) columns.
pub fn dynamics(x: &[f64], minv: &Matrix2<f64>, minv_b_delta: &Vector2<f64>) -> (Vector2<f64>, M8) {
    let (nu_dot, rows) = dynamics_rows(x, minv, minv_b_delta);
    (nu_dot, jacobian(&rows))
}

/// Rows 1 and 2 (v̇′, ṙ′) of the Jacobian, the only ones that are not +0.
type JacobianRows = SMatrix<f64, 2, 8>;

/// f(x̂) and the nonzero rows of F (see [`dynamics`]).
fn dynamics_rows(
    x: &[f64],
    minv: &Matrix2<f64>,
    minv_b_delta: &Vector2<f64>,
) -> (Vector2<f64>, JacobianRows) {
    let (v, r) = (x[1], x[2]);
    let n = Matrix2::new(x[4], x[5], x[6], x[7]);
    let a = -minv * n;
    let nu_dot = a * Vector2::new(v, r) + minv_b_delta;
    let mut f = JacobianRows::zeros();
    for i in 0..2 {
        for j in 0..2 {
            f[(i, 1 + j)] = a[(i, j)];
        }
        f[(i, 4)] = -minv[(i, 0)] * v;
        f[(i, 5)] = -minv[(i, 0)] * r;
        f[(i, 6)] = -minv[(i, 1)] * v;
        f[(i, 7)] = -minv[(i, 1)] * r;
    }
    (nu_dot, f)
}

/// F from its nonzero rows (+0 elsewhere).
fn jacobian(rows: &JacobianRows) -> M8 {
    let mut f = M8::zeros();
    f.fixed_rows_mut::<2>(1).copy_from(rows);
    f
}

/// F P for the Jacobian F with nonzero rows `rows`, bit for bit equal to the dense product
/// `F * P` without its 384 multiplications by +0.
///
/// nalgebra forms each element as the sum `F_i0 P_0j + F_i1 P_1j + …` in that order, and so
/// are the elements of the two nonzero rows summed here. In every other row each term `+0 · P_kj` is a zero
/// with the sign of `P_kj`, and a sum of zeros is −0 exactly when every term is −0: such an
/// element is −0 when the whole column of P is negative-signed, else +0. A P with a non-finite
/// element (0 · ∞ is NaN) takes the dense product.
fn jacobian_times(rows: &JacobianRows, p: &M8) -> M8 {
    const EXP: u64 = 0x7ff0_0000_0000_0000;
    let f = &rows.data.0; // columns of the 2 × 8 rows
    let mut non_finite = false;
    let mut out = [[0.0; 8]; 8];
    for (col, p_col) in out.iter_mut().zip(&p.data.0) {
        let (mut s1, mut s2) = (f[0][0] * p_col[0], f[0][1] * p_col[0]);
        // `term + sum`, nalgebra's operand order
        #[allow(clippy::assign_op_pattern)]
        for k in 1..8 {
            s1 = f[k][0] * p_col[k] + s1;
            s2 = f[k][1] * p_col[k] + s2;
        }
        let mut all_negative = !0u64;
        for v in p_col {
            let b = v.to_bits();
            all_negative &= b;
            non_finite |= b & EXP == EXP;
        }
        let zero = f64::from_bits(all_negative & (1 << 63));
        *col = [zero, s1, s2, zero, zero, zero, zero, zero];
    }
    if non_finite {
        return jacobian(rows) * p;
    }
    M8::from_data(nalgebra::ArrayStorage(out))
}

/// d/dt′ of [x̂, P]: f(x̂) and F P + P Fᵀ + Q.
fn derivative(
    y: &[f64; NPROP],
    minv: &Matrix2<f64>,
    bd: &Vector2<f64>,
    qs: f64,
    qp: f64,
) -> [f64; NPROP] {
    let (nu_dot, rows) = dynamics_rows(&y[..8], minv, bd);
    let p = M8::from_column_slice(&y[8..]);
    let fp = jacobian_times(&rows, &p);
    let mut pd = fp + fp.transpose();
    for i in 0..4 {
        pd[(i, i)] += qs;
        pd[(i + 4, i + 4)] += qp;
    }
    let mut out = [0.0; NPROP];
    out[1] = nu_dot[0];
    out[2] = nu_dot[1];
    out[8..].copy_from_slice(pd.as_slice());
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hull::container_ship::{
        ContainerShip, ContainerShipInputs, L as CS_L, LIN_B, LIN_M, LIN_N,
    };
    use crate::hull::nomoto::{NomotoInputs, NomotoModel, NomotoShip};
    use crate::hull::DEG;
    use crate::manoeuvre::{
        run, turning_circle, ManoeuvreGenerator, ManoeuvreKind, ManoeuvreShip, Sample,
        TurningCircleMetrics,
    };
    use crate::math::{atan2, sin};
    use crate::random::NoiseStream;

    /// The Esso Osaka truth of [Taylor2000, Table 2.3].
    const ESSO: [f64; 4] = [0.0244, 0.0138, 1.4578e-3, 8.093e-4];

    fn zigzag_10_10() -> ManoeuvreGenerator {
        ManoeuvreGenerator::new(
            ManoeuvreKind::ZigZag {
                rudder: 10.0 * DEG,
                check: 10.0 * DEG,
            },
            0.0,
            0.0,
        )
    }

    fn turn_10() -> ManoeuvreGenerator {
        ManoeuvreGenerator::new(
            ManoeuvreKind::TurningCircle { rudder: 10.0 * DEG },
            0.0,
            0.0,
        )
    }

    /// A linear sway-yaw ship (`NomotoShip`) with a rate-limited rudder, for `manoeuvre::run`.
    struct LinearRun {
        ship: NomotoShip,
        rudder: f64,
        rate_max: f64,
        rudder_max: f64,
    }

    impl LinearRun {
        fn new(m: [[f64; 2]; 2], n: [f64; 4], b: [f64; 2], l: f64, u: f64, rate: f64) -> Self {
            let model = NomotoModel::SwayYaw {
                m,
                n: [[n[0], n[1]], [n[2], n[3]]],
                b,
            };
            LinearRun {
                ship: NomotoShip::new(model, l, u).unwrap(),
                rudder: 0.0,
                rate_max: rate,
                rudder_max: 35.0 * DEG,
            }
        }
    }

    impl ManoeuvreShip for LinearRun {
        fn sample(&self) -> Sample {
            let o = self.ship.outputs();
            Sample {
                t: o.time,
                x: o.x,
                y: o.y,
                psi: o.heading,
                r: o.yaw_rate,
                speed: o.speed_over_ground,
                roll: 0.0,
                drift: atan2(o.sway_velocity, self.ship.speed),
                rudder: self.rudder,
                rudder_command: 0.0,
            }
        }
        fn advance(&mut self, cmd: f64, h: f64) {
            // Rate-limited rudder (exact over h when the limit holds), fed as its step average.
            let target = cmd.clamp(-self.rudder_max, self.rudder_max);
            let d = (target - self.rudder).clamp(-self.rate_max * h, self.rate_max * h);
            let mid = self.rudder + 0.5 * d;
            self.rudder += d;
            self.ship.step(
                &NomotoInputs {
                    rudder: mid,
                    ..Default::default()
                },
                h,
            );
        }
    }

    /// The container ship at a fixed shaft command, for `manoeuvre::run`.
    struct CsRun(ContainerShip, f64);

    impl ManoeuvreShip for CsRun {
        fn sample(&self) -> Sample {
            let o = self.0.outputs();
            Sample {
                t: o.time,
                x: o.x,
                y: o.y,
                psi: o.heading,
                r: o.r,
                speed: o.speed,
                roll: o.roll,
                drift: o.drift_angle,
                rudder: o.rudder,
                rudder_command: 0.0,
            }
        }
        fn advance(&mut self, cmd: f64, h: f64) {
            let inp = ContainerShipInputs {
                rudder_command: cmd,
                shaft_command_rpm: self.1,
                ..Default::default()
            };
            self.0.step(&inp, h);
        }
    }

    fn esso() -> ([[f64; 2]; 2], [f64; 2], f64, f64) {
        let s = NomotoShip::esso_osaka();
        let NomotoModel::SwayYaw { m, b, .. } = s.model else {
            unreachable!()
        };
        (m, b, s.length, s.speed)
    }

    fn esso_params(q: f64, fq: f64, p0_factor: f64, p0_var: f64) -> ParameterEkfParams {
        let (m, b, l, u) = esso();
        let mut p = ParameterEkfParams::table_4_1(l, u, 1.0, m, b, ESSO.map(|c| c * p0_factor));
        p.process_noise = q;
        p.coefficient_noise = fq;
        p.initial_coefficient_variance = p0_var;
        p
    }

    /// The Esso Osaka 10/10 zig-zag (rudder stepped and held over h = 1 s, as the filter sees
    /// it, executed at 0) for `t_end` s; the filter gets u = U, n′ = 1 and v, r plus
    /// `noise_sd`·N(0, 1) in nondimensional units (seed `seed`). Returns the filter and the
    /// relative errors (p̂ − p)/p after each step.
    fn esso_zigzag(
        params: ParameterEkfParams,
        t_end: f64,
        noise_sd: f64,
        seed: u64,
    ) -> (ParameterEkf, Vec<(f64, [f64; 4])>) {
        let mut ship = NomotoShip::esso_osaka();
        let (l, u) = (ship.length, ship.speed);
        let mut gen = zigzag_10_10();
        let mut f = ParameterEkf::new(params, 0.0).unwrap();
        let (mut nv, mut nr) = (NoiseStream::new(seed, 1), NoiseStream::new(seed, 2));
        let h = 1.0;
        let mut rec = Vec::new();
        for k in 0..(t_end / h).round() as usize {
            let t = k as f64 * h;
            let o = ship.outputs();
            let delta = gen.command(t, o.heading, o.yaw_rate);
            let v = o.sway_velocity + noise_sd * nv.normal() * u;
            let r = o.yaw_rate + noise_sd * nr.normal() * u / l;
            f.step(t, h, [u, v, r, 1.0], delta);
            let inp = NomotoInputs {
                rudder: delta,
                ..Default::default()
            };
            ship.step(&inp, h);
            let c = f.coefficients();
            rec.push((t + h, [0, 1, 2, 3].map(|i| (c[i] - ESSO[i]) / ESSO[i])));
        }
        (f, rec)
    }

    /// First time from which all relative errors stay within `tol` (NaN: never).
    fn settle_time(rec: &[(f64, [f64; 4])], tol: f64) -> f64 {
        let mut t_in = f64::NAN;
        for (t, e) in rec {
            if e.iter().all(|x| x.abs() <= tol) {
                if t_in.is_nan() {
                    t_in = *t;
                }
            } else {
                t_in = f64::NAN;
            }
        }
        t_in
    }

    /// 10° turning circle (1500 s, h = 0.5 s, rudder 2.33°/s) of the Esso Osaka linear model
    /// with coefficients `n`.
    fn esso_turn(n: [f64; 4]) -> TurningCircleMetrics {
        let (m, b, l, u) = esso();
        let mut ship = LinearRun::new(m, n, b, l, u, 2.33 * DEG);
        turning_circle(&run(&mut ship, &mut turn_10(), 0.5, 1500.0), 0.0).unwrap()
    }

    /// Esso Osaka verification [Taylor2000, sec. 2.3], noise-free: the filter model is the plant (Esso Osaka linear
    /// sway-yaw model, `NomotoShip::esso_osaka()`: [Taylor2000, Table 2.3] N with the documented assumed M, b,
    /// U = 10 kn, L/U = 63.2 s), Q = FQ = 0, R = 0.01 ([Taylor2000, Table 4.1], "in all cases",
    /// [Taylor2000, sec. 4.3.1]),
    /// exact measurements every 1 s of a 10/10 zig-zag. From x̂₀ = 0.5× and 1.5× the truth
    /// (P₀ = 1e-3 on the coefficients, σ ≈ 1.3× −Y′_v) all four coefficients end within 1 %
    /// after 30 min (measured 0.38 % and 0.12 %; within 1 % from 1107 s and 693 s), and the 10° tactical diameter of the
    /// identified model is within 5 % of the true one ([Taylor2000, Fig. 2-7]'s "less than 5 %"; measured
    /// ≈ 0.1 %).
    ///
    /// Not reproduced: the thesis's "about 3 minutes" to converge [Taylor2000, sec. 2.3]. Ours: all four stay
    /// within 1 % from 1107 s (17.5 L/U) with P₀ = 1e-3 and x̂₀ = 0.5×, from 515 s with P₀ = 1e-2 and from
    /// 220 s with R = 1e-4 — with Q = 0 the EKF is a recursive least-squares fit whose prior
    /// (x̂₀, P₀) decays as R/(P₀·information), so the time depends on P₀, R and the speed
    /// (time scale L/U), none of which the thesis gives for this run.
    #[test]
    fn at10_esso_osaka_noise_free_converges_to_table_2_3() {
        let true_turn = esso_turn(ESSO);
        for (factor, want) in [(0.5, 1e-2), (1.5, 1e-2)] {
            let (f, rec) = esso_zigzag(esso_params(0.0, 0.0, factor, 1e-3), 1800.0, 0.0, 1);
            let e = rec.last().unwrap().1;
            println!(
                "x0 = {factor} x truth: final relative errors {e:?}; within 1 % from {} s, 5 % from {} s",
                settle_time(&rec, 0.01),
                settle_time(&rec, 0.05)
            );
            assert!(e.iter().all(|x| x.abs() < want), "{e:?}");
            let t = esso_turn(f.coefficients());
            let err = t.tactical_diameter / true_turn.tactical_diameter - 1.0;
            println!(
                "tactical diameter {} vs {} m ({err:+.4})",
                t.tactical_diameter, true_turn.tactical_diameter
            );
            assert!(err.abs() < 0.05);
        }
        // The other settings quoted in the doc comment.
        let (_, rec) = esso_zigzag(esso_params(0.0, 0.0, 0.5, 1e-2), 1800.0, 0.0, 1);
        assert!(settle_time(&rec, 0.01) < 600.0);
    }

    /// The Esso Osaka verification with measurement noise. The thesis prints no spread for the Esso Osaka run; the
    /// closest statement is [Taylor2000, Fig. 2-7] (10° turn "less than 5 %" error in turning diameter), so
    /// that is the bound here: with N(0, 0.01²) noise on v′ and r′ (5 % and 2 % of the
    /// zig-zag's peak |v′| = 0.20, |r′| = 0.48) and the exact filter model (Q = FQ = 0,
    /// R = 0.01), the 67 % running mean of every coefficient is within 5 % (measured 0.1-1.3 %
    /// for seeds 1-3) and the identified tactical diameter within 5 %.
    ///
    /// Found on the way (not asserted): (a) noise of the size the filter assumes, σ = √R = 0.1,
    /// biases the estimates by −35 … −46 % after 1 h — the EKF as a parameter estimator is
    /// biased when the noise is large against the signal (Ljung 1979: the gain's dependence on
    /// the parameters is neglected); the thesis calls R = 0.01 "conservative" (footnote in
    /// [Taylor2000, sec. 4.3.1]),
    /// i.e. larger than the actual noise; (b) with the DDG-51 settings Q = 0.05, FQ = 0.01 on
    /// this exact model the noise-free estimates still converge (0.0 % after 1 h) but with
    /// σ = 0.01 the coefficients random-walk far away (−N_v × 46) — FQ = 0.01 per unit t′ is
    /// large against coefficients of 1e-3.
    #[test]
    fn at10_esso_osaka_with_measurement_noise() {
        let true_turn = esso_turn(ESSO);
        for seed in 1..=3 {
            let (f, _) = esso_zigzag(esso_params(0.0, 0.0, 0.5, 1e-3), 3600.0, 0.01, seed);
            let a = f.averaged_coefficients();
            let e = [0, 1, 2, 3].map(|i| a[i] / ESSO[i] - 1.0);
            let t = esso_turn(a);
            let err = t.tactical_diameter / true_turn.tactical_diameter - 1.0;
            println!("seed {seed}: mean of last 67 % {a:?}, errors {e:?}, tactical {err:+.4}");
            assert!(e.iter().all(|x| x.abs() < 0.05), "{e:?}");
            assert!(err.abs() < 0.05);
        }
    }

    /// Container-ship identification run: plant at the 80 rpm equilibrium (U₀ = 8.38 m/s),
    /// 10/10 zig-zag for `t_end` s, samples every 1 s of u, v, r, n (+ `noise_sd`·N(0, 1) in
    /// nondimensional units); the filter gets the step average of the actual (rate-limited)
    /// rudder. Filter model: M and b from the (v, r) block of the linearised model
    /// (`LIN_M`, `LIN_B`, from MSS `Lcontainer.m`), x̂₀ = 0.5 × the (v, r) block of
    /// `LIN_N`.
    fn container_identify(
        params: impl Fn(ParameterEkfParams) -> ParameterEkfParams,
        t_end: f64,
        noise_sd: f64,
        seed: u64,
    ) -> (ParameterEkf, f64) {
        let rpm = 80.0;
        let mut ship = ContainerShip::at_equilibrium(rpm).unwrap();
        let u0 = ship.outputs().u;
        let (m, b, n) = container_mbn();
        let p = ParameterEkfParams::table_4_1(CS_L, u0, rpm, m, b, n.map(|c| 0.5 * c));
        let mut f = ParameterEkf::new(params(p), 0.0).unwrap();
        let mut gen = zigzag_10_10();
        let mut ns: Vec<NoiseStream> = (0..4).map(|c| NoiseStream::new(seed, c)).collect();
        let h = 1.0;
        for k in 0..(t_end / h).round() as usize {
            let t = k as f64 * h;
            let o = ship.outputs();
            let cmd = gen.command(t, o.heading, o.r);
            let z = [
                o.u + noise_sd * ns[0].normal() * u0,
                o.v + noise_sd * ns[1].normal() * u0,
                o.r + noise_sd * ns[2].normal() * u0 / CS_L,
                o.shaft_rpm + noise_sd * ns[3].normal() * rpm,
            ];
            let inp = ContainerShipInputs {
                rudder_command: cmd,
                shaft_command_rpm: rpm,
                ..Default::default()
            };
            ship.step(&inp, h);
            let delta = 0.5 * (o.rudder + ship.outputs().rudder);
            f.step(t, h, z, delta);
        }
        (f, u0)
    }

    fn container_mbn() -> ([[f64; 2]; 2], [f64; 2], [f64; 4]) {
        (
            [[LIN_M[0][0], LIN_M[0][1]], [LIN_M[1][0], LIN_M[1][1]]],
            [LIN_B[0], LIN_B[1]],
            [LIN_N[0][0], LIN_N[0][1], LIN_N[1][0], LIN_N[1][1]],
        )
    }

    /// Turning circle with rudder `deg` of the plant and of the linear model with coefficients
    /// `n` (same 5°/s rudder rate, constant speed U₀), 3000 s at h = 0.5 s.
    fn container_turns(
        n: [f64; 4],
        u0: f64,
        deg: f64,
    ) -> (TurningCircleMetrics, TurningCircleMetrics) {
        let gen =
            ManoeuvreGenerator::new(ManoeuvreKind::TurningCircle { rudder: deg * DEG }, 0.0, 0.0);
        let mut plant = CsRun(ContainerShip::at_equilibrium(80.0).unwrap(), 80.0);
        let tp = turning_circle(&run(&mut plant, &mut gen.clone(), 0.5, 3000.0), 0.0).unwrap();
        let (m, b, _) = container_mbn();
        let mut lin = LinearRun::new(m, n, b, CS_L, u0, 5.0 * DEG);
        let tl = turning_circle(&run(&mut lin, &mut gen.clone(), 0.5, 3000.0), 0.0).unwrap();
        (tp, tl)
    }

    /// Post-identification validation [Taylor2000, sec. 4.3.4] on ContainerShip as the nonlinear plant, with the [Taylor2000, Table 4.1]
    /// settings (Q = 0.05, FQ = 0.01, R = 0.01), a 30-min 10/10 zig-zag and the mean of the
    /// last 67 % of the estimates. The identified linear model turns tighter than the plant at
    /// 10° rudder, as in the thesis [Taylor2000, sec. 4.3.4]:
    /// * tactical diameter (180° heading change): −15.1 % noise-free, −13.1 % with
    ///   N(0, 0.001²) measurement noise (thesis "approximately 15 %", identified tighter);
    ///   asserted within 20 % and negative;
    /// * steady turning diameter: −24.0 % noise-free (−21.6 % with noise): **not within 20 %**,
    ///   asserted within 26 %. Why: no linear model can match the plant's steady turns at all
    ///   rudder angles. The plant's steady r′/δ falls from 2.61 at 2° to 1.94 at 5° and 1.44
    ///   at 10° (nonlinear damping Y_vvv, N_rrr, N_vvr … of MSS `container.m`); the
    ///   zig-zag (peak |r′| = 0.23) fits K′ = 1.91, matching the 5° steady diameter within
    ///   1.3 % (asserted within 5 %) while the 2° turn is 36 % too wide and the 10° turn 24 %
    ///   too tight. The thesis's DDG-51 plant [43] is not given, so its 15 % cannot be tied to
    ///   a definition of the diameter; the tactical one is the closer reading of its trajectory
    ///   plot [Taylor2000, Fig. 4-11].
    /// * Speed loss: the plant's 10° speed loss is 20.5 % (thesis ≈ 20 %), asserted 18-23 %; its
    ///   shaft speed is governed (MSS `container.m`), so the thesis's ≈ 10 % rpm loss has
    ///   no counterpart.
    ///
    /// Robustness measured while writing this (not asserted): the result does not depend on
    /// x̂₀ (0, 0.5, 1, 2 × LIN_N) or P₀ (1e-4 … 1e-2) or the run length (20-60 min: −14.3 …
    /// −15.1 % tactical); larger noise pushes the estimates up (identified model wider):
    /// σ = 0.003 gives +0.4 %, σ = 0.01 gives +110 % — with noisy data FQ = 0.01 is too large
    /// (FQ = 1e-4 at σ = 0.01: −6 % tactical, −12 % steady).
    #[test]
    fn at11_container_ship_identified_turning_diameter() {
        for (noise, seed) in [(0.0, 1), (0.001, 1)] {
            let (f, u0) = container_identify(|p| p, 1800.0, noise, seed);
            let a = f.averaged_coefficients();
            let (tp, tl) = container_turns(a, u0, 10.0);
            let tact = tl.tactical_diameter / tp.tactical_diameter - 1.0;
            let steady = tl.steady_diameter / tp.steady_diameter - 1.0;
            println!(
                "noise {noise}: coefficients {a:?} (Nomoto T', K' {:?}); plant D_tact {:.0} m, \
                 D_s {:.0} m, speed loss {:.3}; identified {tact:+.3} tactical, {steady:+.3} steady",
                f.identified_nomoto(),
                tp.tactical_diameter,
                tp.steady_diameter,
                tp.speed_loss
            );
            assert!(tact < 0.0 && tact > -0.20, "{tact}");
            assert!(steady < 0.0 && steady > -0.26, "{steady}");
            assert!((0.18..0.23).contains(&tp.speed_loss));
            if noise == 0.0 {
                let (tp5, tl5) = container_turns(a, u0, 5.0);
                let e5 = tl5.steady_diameter / tp5.steady_diameter - 1.0;
                println!("5 deg steady diameter {e5:+.4}");
                assert!(e5.abs() < 0.05);
            }
        }
    }

    /// The analytic Jacobian (derived here) equals central finite differences of f.
    /// `jacobian_times` equals nalgebra's `F * P` bit for bit: Jacobians of random states and
    /// random P with signed zeros, negative-signed columns, tiny (underflowing) and huge
    /// entries; P with ±∞ or NaN takes the dense product (NaN compared as NaN: payloads are
    /// not specified).
    #[test]
    fn jacobian_times_equals_the_dense_product() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let value = |rng: &mut rand_chacha::ChaCha8Rng, special: bool| -> f64 {
            let sign = if rng.gen_bool(0.5) { -1.0 } else { 1.0 };
            match rng.gen_range(0..if special { 8 } else { 6 }) {
                0 => sign * 0.0,
                1 => sign * 1e-300 * rng.gen::<f64>(),
                2 => sign * 1e300 * rng.gen::<f64>(),
                6 => sign * f64::INFINITY,
                7 => f64::NAN,
                _ => sign * rng.gen::<f64>(),
            }
        };
        let minv = Matrix2::new(0.8, -0.1, 0.05, 1.3);
        let mut checked = 0;
        for case in 0..20_000 {
            let x: Vec<f64> = (0..8).map(|_| value(&mut rng, false)).collect();
            let (_, rows) = dynamics_rows(&x, &minv, &Vector2::new(0.01, -0.02));
            let f = jacobian(&rows);
            let full = dynamics(&x, &minv, &Vector2::new(0.01, -0.02)).1;
            assert!(f
                .iter()
                .zip(full.iter())
                .all(|(a, b)| a.to_bits() == b.to_bits()));
            let special = rng.gen_bool(0.05);
            let negative_columns = rng.gen_bool(0.3);
            let p = M8::from_fn(|_, j| {
                let v = value(&mut rng, special);
                if negative_columns && j % 2 == 0 {
                    -v.abs()
                } else {
                    v
                }
            });
            let (want, got) = (f * p, jacobian_times(&rows, &p));
            for (w, g) in want.iter().zip(got.iter()) {
                assert!(
                    w.to_bits() == g.to_bits() || (w.is_nan() && g.is_nan()),
                    "case {case}: dense {w:e}, structured {g:e}"
                );
                checked += usize::from(*w == 0.0 && w.is_sign_negative());
            }
        }
        assert!(checked > 1000, "too few −0 elements exercised: {checked}");
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        let (m, b, _, _) = esso();
        let minv = Matrix2::new(m[0][0], m[0][1], m[1][0], m[1][1])
            .try_inverse()
            .unwrap();
        let bd = minv * Vector2::new(b[0], b[1]) * 0.1;
        let x = [1.02, 0.03, -0.2, 0.97, 0.02, 0.011, 1.2e-3, 9e-4];
        let (_, f) = dynamics(&x, &minv, &bd);
        for j in 0..8 {
            let d = 1e-6 * (1.0 + x[j].abs());
            let (mut xp, mut xm) = (x, x);
            xp[j] += d;
            xm[j] -= d;
            let (fp, _) = dynamics(&xp, &minv, &bd);
            let (fm, _) = dynamics(&xm, &minv, &bd);
            for i in 0..2 {
                let fd = (fp[i] - fm[i]) / (2.0 * d);
                assert!(
                    (fd - f[(1 + i, j)]).abs() < 1e-6 * (1.0 + fd.abs()),
                    "({i},{j})"
                );
            }
        }
        for i in [0, 3, 4, 5, 6, 7] {
            assert!(f.row(i).iter().all(|&v| v == 0.0));
        }
    }

    /// One update equals [Taylor2000, eqs. (2.19)-(2.21)] written out with H = [I₄ 0]; the running mean is the
    /// mean of the last round(0.67 k) a-posteriori estimates, checked against the stored list.
    #[test]
    fn update_and_running_mean() {
        let p = esso_params(0.05, 0.01, 0.7, 1e-3);
        let mut f = ParameterEkf::new(p.clone(), 0.0).unwrap();
        f.propagate(0.1, 30.0);
        let (x0, p0) = (f.x, f.p);
        let (l, u) = (p.length, p.speed);
        let z = SVector::<f64, 4>::new(1.01, 0.02, -0.1, 0.99);
        f.update(z[0] * u, z[1] * u, z[2] * u / l, z[3] * p.shaft_speed);
        let mut h = SMatrix::<f64, 4, 8>::zeros();
        for i in 0..4 {
            h[(i, i)] = 1.0;
        }
        let s = h * p0 * h.transpose() + M4::identity() * p.measurement_noise;
        let k = p0 * h.transpose() * s.try_inverse().unwrap();
        let x1 = x0 + k * (z - h * x0);
        let p1 = (M8::identity() - k * h) * p0;
        assert!((f.x - x1).abs().max() < 1e-12);
        assert!((f.p - p1).abs().max() < 1e-12 * p0.abs().max());

        let mut g = ParameterEkf::new(p, 0.0).unwrap();
        let mut hist: Vec<[f64; 4]> = Vec::new();
        for k in 0..200 {
            let t = k as f64;
            let s = sin(0.05 * t);
            g.step(t, 1.0, [u, 0.02 * s * u, 0.2 * s * u / l, 1.0], 0.1 * s);
            hist.push(g.sums.last().copied().unwrap());
            let n = hist.len();
            let w = ((0.67 * n as f64).round() as usize).max(1);
            let mut mean = [0.0; 4];
            for j in 0..4 {
                // recover the a-posteriori estimates from the prefix sums
                let vals: Vec<f64> = (0..n)
                    .map(|i| hist[i][j] - if i == 0 { 0.0 } else { hist[i - 1][j] })
                    .collect();
                mean[j] = vals[n - w..].iter().sum::<f64>() / w as f64;
            }
            let a = g.averaged_coefficients();
            for j in 0..4 {
                assert!((a[j] - mean[j]).abs() < 1e-12 * mean[j].abs().max(1e-3));
            }
        }
        assert_eq!(g.updates(), 200);
    }

    /// Sample timing: with h = 0.25 s and a 1 s sample interval, one update per 4 steps; a
    /// clone (the FMU state) continues bit-identically; serde round trip.
    #[test]
    fn sample_timing_and_state_snapshot() {
        let mut f = ParameterEkf::new(esso_params(0.05, 0.01, 0.5, 1e-3), 0.0).unwrap();
        for k in 0..40 {
            f.step(k as f64 * 0.25, 0.25, [5.0, 0.1, 0.001, 1.0], 0.05);
        }
        assert_eq!(f.updates(), 10);
        let bytes = bincode::serialize(&f).unwrap();
        let mut g: ParameterEkf = bincode::deserialize(&bytes).unwrap();
        let mut c = f.clone();
        for k in 40..80 {
            let t = k as f64 * 0.25;
            f.step(t, 0.25, [5.0, 0.1, 0.001, 1.0], 0.05);
            g.step(t, 0.25, [5.0, 0.1, 0.001, 1.0], 0.05);
            c.step(t, 0.25, [5.0, 0.1, 0.001, 1.0], 0.05);
        }
        assert_eq!(f, g);
        assert_eq!(f, c);
    }

    #[test]
    fn rejects_bad_parameters() {
        let mut p = esso_params(0.05, 0.01, 0.5, 1e-3);
        p.measurement_noise = 0.0;
        let e = ParameterEkf::new(p, 0.0).unwrap_err();
        assert!(e.contains("measurement_noise"), "{e}");
        let mut p = esso_params(0.05, 0.01, 0.5, 1e-3);
        p.mass = [[1.0, 2.0], [2.0, 4.0]];
        let e = ParameterEkf::new(p, 0.0).unwrap_err();
        assert!(e.contains("determinant"), "{e}");
        let mut p = esso_params(0.05, 0.01, 0.5, 1e-3);
        p.averaging_fraction = 1.5;
        assert!(ParameterEkf::new(p, 0.0).is_err());
    }
}
