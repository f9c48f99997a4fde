//! Closed-form references: the Jacobi elliptic functions by the AGM (descending Landen)
//! method, the simple pendulum, and the Chaplygin sleigh of docs/theory.md V11.

/// `(sn, cn, dn)(u | m)` for `0 ≤ m < 1` by the arithmetic-geometric mean, i.e. the
/// descending Landen transformation: Abramowitz & Stegun, Handbook of Mathematical
/// Functions, §16.4 (16.4.1–16.4.3). With $a_0 = 1$, $b_0 = \sqrt{1-m}$,
/// $c_0 = \sqrt m$, iterate $a_{n} = (a_{n-1} + b_{n-1})/2$, $b_n = \sqrt{a_{n-1}b_{n-1}}$,
/// $c_n = (a_{n-1} - b_{n-1})/2$ until $c_N$ is negligible, set
/// $\varphi_N = 2^N a_N u$ and descend with
/// $\sin(2\varphi_{n-1} - \varphi_n) = (c_n/a_n)\sin\varphi_n$; then
/// $\operatorname{sn} = \sin\varphi_0$, $\operatorname{cn} = \cos\varphi_0$, and
/// $\operatorname{dn} = \sqrt{1 - m\operatorname{sn}^2}$ (A&S 16.9.1; the quotient form
/// 16.4.4 is 0/0 at $u = K$).
pub fn jacobi(u: f64, m: f64) -> (f64, f64, f64) {
    assert!((0.0..1.0).contains(&m), "parameter m = {m} outside [0, 1)");
    let mut a = [0.0_f64; 16];
    let mut c = [0.0_f64; 16];
    a[0] = 1.0;
    let mut b = (1.0 - m).sqrt();
    c[0] = m.sqrt();
    let mut n = 0;
    while c[n].abs() > f64::EPSILON && n < 15 {
        let (an, bn) = (a[n], b);
        n += 1;
        a[n] = 0.5 * (an + bn);
        b = (an * bn).sqrt();
        c[n] = 0.5 * (an - bn);
    }
    let mut phi = f64::from(1u32 << n) * a[n] * u;
    for k in (1..=n).rev() {
        phi = 0.5 * (phi + (c[k] / a[k] * phi.sin()).asin());
    }
    let sn = phi.sin();
    (sn, phi.cos(), (1.0 - m * sn * sn).sqrt())
}

/// $K(1/2)$, docs/models.md (`pendulum`).
#[allow(clippy::excessive_precision)] // the digits as printed in the reference
pub const K_HALF: f64 = 1.854_074_677_301_371_918_43;

/// Exact state `(x, y, ẋ, ẏ)` of the `pendulum` model (l = 1, g = 9.81, released at
/// rest at x = l, y = 0). docs/models.md: with θ from the downward vertical,
/// $\sin(\theta/2) = k\,\operatorname{sn}(K - \omega_0 t \mid m = 1/2)$, $k = 1/\sqrt2$,
/// $\omega_0 = \sqrt{g/l}$. Differentiating, with $\cos(\theta/2) = \operatorname{dn}$,
/// $\dot\theta = -2k\omega_0\operatorname{cn}(K - \omega_0 t)$.
pub fn pendulum(t: f64) -> [f64; 4] {
    let (l, g) = (1.0, 9.81_f64);
    let w0 = (g / l).sqrt();
    let k = std::f64::consts::FRAC_1_SQRT_2;
    let (sn, cn, _) = jacobi(K_HALF - w0 * t, 0.5);
    let theta = 2.0 * (k * sn).asin();
    let thd = -2.0 * k * w0 * cn;
    [
        l * theta.sin(),
        -l * theta.cos(),
        l * theta.cos() * thd,
        l * theta.sin() * thd,
    ]
}

/// The pendulum period $4K/\omega_0$ = 2.36784194757624 s (docs/models.md).
pub const PENDULUM_PERIOD: f64 = 2.367_841_947_576_24;

/// docs/theory.md V11 (Chaplygin sleigh, m = 2, J_c = 0.05, a = 0.3, v0 = 1, ω0 = 0.5):
/// `(t, v, ω, φ)` from the table of expected values.
pub const SLEIGH_V11: [(f64, f64, f64, f64); 3] = [
    (
        1.0,
        1.014_200_804_33,
        0.035_719_741_683_2,
        0.176_360_706_663,
    ),
    (
        2.0,
        1.014_272_774_73,
        0.002_534_025_326_5,
        0.188_903_202_544,
    ),
    (
        5.0,
        1.014_273_138_75,
        9.046_336_283_53e-7,
        0.189_860_567_654,
    ),
];
