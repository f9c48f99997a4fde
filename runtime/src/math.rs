//! Sine and cosine as generated code calls them: [`sin`], [`cos`] and [`sin_cos`].
//!
//! A mechanism's functions spend much of their time in trigonometry (about a fifth of
//! a simulation of Andrews' squeezer went to glibc's `sin`, `cos` and `sincos`, which
//! also save and restore the rounding mode on every call). These are inlinable,
//! branch-light versions with the accuracy of the C library's in practice: at most one
//! unit in the last place from glibc's result over millions of arguments (the tests
//! below state the measured figures).
//!
//! **Method** (fdlibm's, in Rust):
//! 1. Reduction: `x = n·π/2 + y` with `|y| ≲ π/4`, `n = round(x·2/π)`, by Cody and
//!    Waite's scheme with π/2 in three parts of 33 bits each (`P₁ + P₂ + P₃`, each
//!    with its tail): `n·Pᵢ` is exact while `|n| ≤ 2²⁰`, and the second and third
//!    parts are used only when the first subtraction cancels more than 16, then 49,
//!    bits (x near a multiple of π/2). `y` is kept as a head and a tail, `y₀ + y₁`.
//! 2. Kernels on `[−π/4, π/4]`: fdlibm's minimax polynomials of degree 13 (sine) and 14
//!    (cosine), error below 2⁻⁵⁸ relative, with the first-order correction of the tail:
//!    `sin(y₀ + y₁) ≈ sin y₀ + (1 − y₀²/2)·y₁`, `cos(y₀ + y₁) ≈ cos y₀ − y₀·y₁`.
//! 3. The quadrant `n mod 4` swaps and negates the pair `(sin y, cos y)` without a
//!    branch; both kernels share `y²` and run side by side.
//!
//! **Bound.** The reduction serves `2⁻²⁶ ≤ |x| < 2²⁰·π/2 ≈ 1.647·10⁶` (the high word
//! of `|x|` below `0x4139_21fb`, fdlibm's "medium" range). Below, `sin x = x` and
//! `cos x = 1 − x²/2` to within rounding (which keeps `sin(−0) = −0`); above, and for
//! infinities and NaN, the functions call `f64::sin` and `f64::cos` (glibc's
//! Payne–Hanek reduction), out of line.
//!
//! The coefficients and the reduction's constants are fdlibm's (`k_sin.c`, `k_cos.c`,
//! `e_rem_pio2.c`, as in FreeBSD's msun), under this notice:
//!
//! > Copyright (C) 1993 by Sun Microsystems, Inc. All rights reserved.
//! >
//! > Developed at SunSoft, a Sun Microsystems, Inc. business.
//! > Permission to use, copy, modify, and distribute this
//! > software is freely granted, provided that this notice
//! > is preserved.

/// 53 bits of 2/π.
const INV_PIO2: f64 = f64::from_bits(0x3FE4_5F30_6DC9_C883);
/// The first 33 bits of π/2, and π/2 − `PIO2_1`.
const PIO2_1: f64 = f64::from_bits(0x3FF9_21FB_5440_0000);
const PIO2_1T: f64 = f64::from_bits(0x3DD0_B461_1A62_6331);
/// The second 33 bits of π/2, and π/2 − (`PIO2_1` + `PIO2_2`).
const PIO2_2: f64 = f64::from_bits(0x3DD0_B461_1A60_0000);
const PIO2_2T: f64 = f64::from_bits(0x3BA3_198A_2E03_7073);
/// The third 33 bits of π/2, and π/2 − (`PIO2_1` + `PIO2_2` + `PIO2_3`).
const PIO2_3: f64 = f64::from_bits(0x3BA3_198A_2E00_0000);
const PIO2_3T: f64 = f64::from_bits(0x397B_839A_2520_49C1);

/// Sine kernel: `sin x ≈ x + S₁x³ + … + S₆x¹³` on `[−π/4, π/4]` (fdlibm `k_sin.c`).
const S1: f64 = f64::from_bits(0xBFC5_5555_5555_5549);
const S2: f64 = f64::from_bits(0x3F81_1111_1110_F8A6);
const S3: f64 = f64::from_bits(0xBF2A_01A0_19C1_61D5);
const S4: f64 = f64::from_bits(0x3EC7_1DE3_57B1_FE7D);
const S5: f64 = f64::from_bits(0xBE5A_E5E6_8A2B_9CEB);
const S6: f64 = f64::from_bits(0x3DE5_D93A_5ACF_D57C);

/// Cosine kernel: `cos x ≈ 1 − x²/2 + C₁x⁴ + … + C₆x¹⁴` on `[−π/4, π/4]` (fdlibm
/// `k_cos.c`).
const C1: f64 = f64::from_bits(0x3FA5_5555_5555_554C);
const C2: f64 = f64::from_bits(0xBF56_C16C_16C1_5177);
const C3: f64 = f64::from_bits(0x3EFA_01A0_19CB_1590);
const C4: f64 = f64::from_bits(0xBE92_7E4F_809C_52AD);
const C5: f64 = f64::from_bits(0x3E21_EE9E_BDB4_B1C4);
const C6: f64 = f64::from_bits(0xBDA8_FAE9_BE88_38D4);

/// High word of `|x|` from which the reduction is not used: `|x| ≥ 2²⁰·π/2` (to the
/// high word's precision), where `n·PIO2_1` would no longer be exact.
const MEDIUM_END: u32 = 0x4139_21fb;
/// High word of `2⁻²⁶`: below it `sin x = x` and `cos x = 1 − x²/2` to within rounding.
const TINY_END: u32 = 0x3e50_0000;

/// The smallest `|x|` for which [`sin`] and [`cos`] call `f64::sin` and `f64::cos`:
/// `2²⁰·π/2` rounded down to the reduction's bound, about `1.647·10⁶`.
pub const REDUCTION_BOUND: f64 = f64::from_bits((MEDIUM_END as u64) << 32);

/// `sin x`, within one unit in the last place of the correctly rounded value.
#[inline(always)]
pub fn sin(x: f64) -> f64 {
    sin_cos(x).0
}

/// `cos x`, within one unit in the last place of the correctly rounded value.
#[inline(always)]
pub fn cos(x: f64) -> f64 {
    sin_cos(x).1
}

/// `(sin x, cos x)` from one reduction: what generated code calls where it needs both.
///
/// An ordinary call where the compiler does not inline it (it does not, into the large
/// generated functions): measured on `pfaff simulate andrews`, forcing it inline made
/// the run slower than calls (949 µs against 883 µs; glibc's calls 989 µs).
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    let hx = high_word(x);
    // One test for both ends: tiny arguments, and huge or non-finite ones.
    if hx.wrapping_sub(TINY_END) >= MEDIUM_END - TINY_END {
        return sin_cos_outside(x);
    }
    let (n, y0, y1) = rem_pio2(x, hx);
    let (s, c) = kernels(y0, y1);
    // x = nπ/2 + y: n = 1 maps (sin y, cos y) to (cos y, −sin y); n = 2 negates both.
    // With masks rather than a branch, which the quadrants of angles would mispredict.
    let q = n as u64;
    let odd = (q & 1).wrapping_neg();
    let sign = (q & 2) << 62;
    let (s, c) = (s.to_bits(), c.to_bits());
    let s1 = (s & !odd) | (c & odd);
    let c1 = (c & !odd) | ((s ^ (1 << 63)) & odd);
    (f64::from_bits(s1 ^ sign), f64::from_bits(c1 ^ sign))
}

/// `(sin, cos)` of two arguments at once, for generated code that needs both of two
/// angles: bitwise the results of two calls of [`sin_cos`] (the same operations lane by
/// lane), in one pass over pairs of doubles. On x86-64 the pass runs in SSE2 registers:
/// seven angles (`andrews`) take 37 ns instead of 48 as three pairs and a single
/// (`runtime/examples/sin_cos_pairs.rs`). An argument outside the fast path (tiny,
/// huge, non-finite, or within 2⁻¹⁶ of a multiple of π/2 relative to its size) sends
/// both to [`sin_cos`].
#[inline]
pub fn sin_cos2(x0: f64, x1: f64) -> ((f64, f64), (f64, f64)) {
    #[cfg(target_arch = "x86_64")]
    {
        sse2::sin_cos2(x0, x1)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        lanes::sin_cos2(x0, x1)
    }
}

/// Whether `(x0, x1)` both take the fast path of [`sin_cos2`]'s first test: the
/// reduction's range (see [`sin_cos`]).
#[inline(always)]
fn both_medium(h0: u32, h1: u32) -> bool {
    h0.wrapping_sub(TINY_END) < MEDIUM_END - TINY_END
        && h1.wrapping_sub(TINY_END) < MEDIUM_END - TINY_END
}

/// Bits of `x`'s magnitude lost by the first subtraction of the reduction, `y₀` its
/// result (see [`rem_pio2`]).
#[inline(always)]
fn lost(hx: u32, y0: f64) -> i32 {
    (hx >> 20) as i32 - ((y0.to_bits() >> 52) & 0x7ff) as i32
}

/// The quadrant's swap and signs of [`sin_cos`] on the kernels' bits `(s, c)`, with
/// `q` the low word of the shifted `x·2/π`.
#[inline(always)]
fn quadrant(q: u64, s: u64, c: u64) -> (f64, f64) {
    let odd = (q & 1).wrapping_neg();
    let sign = (q & 2) << 62;
    let s1 = (s & !odd) | (c & odd);
    let c1 = (c & !odd) | ((s ^ (1 << 63)) & odd);
    (f64::from_bits(s1 ^ sign), f64::from_bits(c1 ^ sign))
}

/// Round to the nearest integer by adding and removing 1.5·2⁵² (see [`rem_pio2`]).
const SHIFT: f64 = 6_755_399_441_055_744.0;

/// The first part of [`rem_pio2`] on two lanes `x`, with the lane operations `add`,
/// `sub`, `mul` and the broadcast `k`: `(shifted, r, w, y₀)`, from which `n` is the low
/// word of `shifted` and `y₁ = (r − y₀) − w`. Shared by the two passes of
/// [`sin_cos2`], so that both run the scalar operations in their order.
macro_rules! reduce2 {
    ($x:expr, $add:ident, $sub:ident, $mul:ident, $k:ident) => {{
        let shifted = $add($mul($x, $k(INV_PIO2)), $k(SHIFT));
        let f = $sub(shifted, $k(SHIFT));
        let r = $sub($x, $mul(f, $k(PIO2_1)));
        let w = $mul(f, $k(PIO2_1T));
        (shifted, r, w, $sub(r, w))
    }};
}

/// [`kernels`] on two lanes `(y₀, y₁)`, operation for operation: `(sin, cos)`.
macro_rules! kernels2 {
    ($y0:expr, $y1:expr, $add:ident, $sub:ident, $mul:ident, $k:ident) => {{
        let (y0, y1) = ($y0, $y1);
        let z = $mul(y0, y0);
        let wz = $mul(z, z);
        let rs = $add(
            $add($k(S2), $mul(z, $add($k(S3), $mul(z, $k(S4))))),
            $mul($mul(z, wz), $add($k(S5), $mul(z, $k(S6)))),
        );
        let v = $mul(z, y0);
        let sn = $sub(
            y0,
            $sub(
                $sub($mul(z, $sub($mul($k(0.5), y1), $mul(v, rs))), y1),
                $mul(v, $k(S1)),
            ),
        );
        let rc = $add(
            $mul(z, $add($k(C1), $mul(z, $add($k(C2), $mul(z, $k(C3)))))),
            $mul(
                $mul(wz, wz),
                $add($k(C4), $mul(z, $add($k(C5), $mul(z, $k(C6))))),
            ),
        );
        let hz = $mul($k(0.5), z);
        let wc = $sub($k(1.0), hz);
        let cs = $add(
            wc,
            $add($sub($sub($k(1.0), wc), hz), $sub($mul(z, rc), $mul(y0, y1))),
        );
        (sn, cs)
    }};
}

/// [`sin_cos2`] on two-element arrays: the portable pass, and the reference of the
/// SSE2 one in the tests.
#[cfg_attr(target_arch = "x86_64", allow(dead_code))]
mod lanes {
    use super::*;

    type X2 = [f64; 2];

    fn zip(a: X2, b: X2, f: impl Fn(f64, f64) -> f64) -> X2 {
        [f(a[0], b[0]), f(a[1], b[1])]
    }
    fn add(a: X2, b: X2) -> X2 {
        zip(a, b, |x, y| x + y)
    }
    fn sub(a: X2, b: X2) -> X2 {
        zip(a, b, |x, y| x - y)
    }
    fn mul(a: X2, b: X2) -> X2 {
        zip(a, b, |x, y| x * y)
    }
    fn k(a: f64) -> X2 {
        [a, a]
    }

    #[inline]
    pub(super) fn sin_cos2(x0: f64, x1: f64) -> ((f64, f64), (f64, f64)) {
        let (h0, h1) = (high_word(x0), high_word(x1));
        if !both_medium(h0, h1) {
            return (sin_cos(x0), sin_cos(x1));
        }
        let x = [x0, x1];
        let (shifted, r, w, y0) = reduce2!(x, add, sub, mul, k);
        if lost(h0, y0[0]) > 16 || lost(h1, y0[1]) > 16 {
            return (sin_cos(x0), sin_cos(x1));
        }
        let y1 = sub(sub(r, y0), w);
        let (sn, cs) = kernels2!(y0, y1, add, sub, mul, k);
        let lane = |i: usize| {
            let q = u64::from(shifted[i].to_bits() as u32);
            quadrant(q, sn[i].to_bits(), cs[i].to_bits())
        };
        (lane(0), lane(1))
    }
}

/// [`sin_cos2`] in SSE2 registers.
#[cfg(target_arch = "x86_64")]
mod sse2 {
    use super::*;
    use std::arch::x86_64::{
        __m128d, _mm_add_pd, _mm_castpd_si128, _mm_cvtsd_f64, _mm_cvtsi128_si64, _mm_mul_pd,
        _mm_set1_pd, _mm_set_pd, _mm_sub_pd, _mm_unpackhi_epi64, _mm_unpackhi_pd,
    };

    #[inline]
    pub(super) fn sin_cos2(x0: f64, x1: f64) -> ((f64, f64), (f64, f64)) {
        // SAFETY: SSE2 is part of the baseline of every x86-64 target (its ABI passes
        // doubles in SSE registers), so the feature `pass` requires is always present.
        #[allow(unsafe_code)]
        unsafe {
            pass(x0, x1)
        }
    }

    /// The lanes of `v`.
    #[inline]
    #[target_feature(enable = "sse2")]
    fn split(v: __m128d) -> [f64; 2] {
        [_mm_cvtsd_f64(v), _mm_cvtsd_f64(_mm_unpackhi_pd(v, v))]
    }

    /// The operations of `lanes::sin_cos2`, two lanes per instruction.
    #[inline]
    #[target_feature(enable = "sse2")]
    fn pass(x0: f64, x1: f64) -> ((f64, f64), (f64, f64)) {
        let (h0, h1) = (high_word(x0), high_word(x1));
        if !both_medium(h0, h1) {
            return (sin_cos(x0), sin_cos(x1));
        }
        let k = |a: f64| _mm_set1_pd(a);
        let (add, sub, mul) = (_mm_add_pd, _mm_sub_pd, _mm_mul_pd);
        let x = _mm_set_pd(x1, x0);
        let (shifted, r, w, y0) = reduce2!(x, add, sub, mul, k);
        let [y00, y01] = split(y0);
        if lost(h0, y00) > 16 || lost(h1, y01) > 16 {
            return (sin_cos(x0), sin_cos(x1));
        }
        let y1 = sub(sub(r, y0), w);
        let (sn, cs) = kernels2!(y0, y1, add, sub, mul, k);
        let qi = _mm_castpd_si128(shifted);
        let q = [
            _mm_cvtsi128_si64(qi) as u64,
            _mm_cvtsi128_si64(_mm_unpackhi_epi64(qi, qi)) as u64,
        ];
        let ([s0, s1], [c0, c1]) = (split(sn), split(cs));
        (
            quadrant(u64::from(q[0] as u32), s0.to_bits(), c0.to_bits()),
            quadrant(u64::from(q[1] as u32), s1.to_bits(), c1.to_bits()),
        )
    }
}

/// The high 32 bits of `|x|`: biased exponent and the top 20 bits of the mantissa.
#[inline(always)]
fn high_word(x: f64) -> u32 {
    ((x.to_bits() >> 32) as u32) & 0x7fff_ffff
}

/// `(sin x, cos x)` outside the reduction's range: tiny, huge or non-finite `x`.
#[cold]
#[inline(never)]
fn sin_cos_outside(x: f64) -> (f64, f64) {
    if high_word(x) < TINY_END {
        // |x| < 2⁻²⁶: x³/6 < 2⁻⁵⁴|x| is below half an ulp of x, and x⁴/24 below a
        // thousandth of an ulp of 1.
        (x, 1.0 - 0.5 * (x * x))
    } else {
        (x.sin(), x.cos())
    }
}

/// `x = n·π/2 + y₀ + y₁` for `2⁻²⁶ ≤ |x| < 2²⁰·π/2` (`hx` the high word of `|x|`),
/// `|y₀| ≲ π/4`, `y₁` the tail of `y₀`: fdlibm's `__ieee754_rem_pio2`, medium case.
#[inline(always)]
fn rem_pio2(x: f64, hx: u32) -> (i32, f64, f64) {
    // round(x·2/π), in round-to-nearest: adding and removing 1.5·2⁵² leaves the integer.
    const SHIFT: f64 = 6_755_399_441_055_744.0;
    // The integer is also the low word of the shifted value (2⁵¹ ≡ 0 mod 2³²), which
    // saves a saturating conversion.
    let shifted = x * INV_PIO2 + SHIFT;
    let n = shifted.to_bits() as i32;
    let f = shifted - SHIFT;
    // f·PIO2_1 is exact (|f| ≤ 2²⁰, PIO2_1 has 33 bits), and so is the subtraction.
    let mut r = x - f * PIO2_1;
    let mut w = f * PIO2_1T;
    let mut y0 = r - w;
    let ex = hx >> 20;
    let lost = |y0: f64| ex as i32 - ((y0.to_bits() >> 52) & 0x7ff) as i32;
    if lost(y0) > 16 {
        // Cancellation: x is near a multiple of π/2. Second part of π/2, good to 118 bits.
        let t = r;
        w = f * PIO2_2;
        r = t - w;
        w = f * PIO2_2T - ((t - r) - w);
        y0 = r - w;
        if lost(y0) > 49 {
            // Third part, 151 bits: enough for every double below the bound.
            let t = r;
            w = f * PIO2_3;
            r = t - w;
            w = f * PIO2_3T - ((t - r) - w);
            y0 = r - w;
        }
    }
    let y1 = (r - y0) - w;
    (n, y0, y1)
}

/// `(sin(x + y), cos(x + y))` for `|x| ≲ π/4` and `|y|` below half an ulp of `x`, with
/// fdlibm's `__kernel_sin(x, y, 1)` and `__kernel_cos(x, y)`.
#[inline(always)]
fn kernels(x: f64, y: f64) -> (f64, f64) {
    let z = x * x;
    let w = z * z;
    // sin: x + S₁x³ + x³·(z·r − y/2)·… arranged as fdlibm, with the tail's term.
    let r = S2 + z * (S3 + z * S4) + z * w * (S5 + z * S6);
    let v = z * x;
    let s = x - ((z * (0.5 * y - v * r) - y) - v * S1);
    // cos: w + ((1 − w) − z/2) + (z·r − x·y), with w = 1 − z/2 rounded and the
    // rounding error of w carried.
    let rc = z * (C1 + z * (C2 + z * C3)) + w * w * (C4 + z * (C5 + z * C6));
    let hz = 0.5 * z;
    let wc = 1.0 - hz;
    let c = wc + (((1.0 - wc) - hz) + (z * rc - x * y));
    (s, c)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Distance in units in the last place between two finite doubles, counting the
    /// representable numbers between them (across zero too).
    fn ulps(a: f64, b: f64) -> u64 {
        let key = |x: f64| {
            let b = x.to_bits() as i64;
            if b < 0 {
                i64::MIN - b
            } else {
                b
            }
        };
        key(a).abs_diff(key(b))
    }

    /// A reproducible uniform stream (SplitMix64).
    struct Rng(u64);
    impl Rng {
        fn next(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            z ^ (z >> 31)
        }
        /// Uniform in `(−a, a)`.
        fn uniform(&mut self, a: f64) -> f64 {
            let u = (self.next() >> 11) as f64 / (1u64 << 53) as f64;
            a * (2.0 * u - 1.0)
        }
    }

    /// Double-double arithmetic (Dekker's, without FMA) for a reference to about 100
    /// bits: `hi + lo` with `|lo| ≤ ulp(hi)/2`.
    #[derive(Clone, Copy, Debug)]
    struct Dd(f64, f64);

    fn two_sum(a: f64, b: f64) -> Dd {
        let s = a + b;
        let bb = s - a;
        Dd(s, (a - (s - bb)) + (b - bb))
    }

    fn fast_two_sum(a: f64, b: f64) -> Dd {
        let s = a + b;
        Dd(s, b - (s - a))
    }

    fn two_prod(a: f64, b: f64) -> Dd {
        let split = |x: f64| {
            let c = 134_217_729.0 * x; // 2²⁷ + 1
            let hi = c - (c - x);
            (hi, x - hi)
        };
        let p = a * b;
        let ((ah, al), (bh, bl)) = (split(a), split(b));
        Dd(p, ((ah * bh - p) + ah * bl + al * bh) + al * bl)
    }

    impl Dd {
        fn add(self, b: Dd) -> Dd {
            let s = two_sum(self.0, b.0);
            fast_two_sum(s.0, s.1 + (self.1 + b.1))
        }
        fn neg(self) -> Dd {
            Dd(-self.0, -self.1)
        }
        fn mul(self, b: Dd) -> Dd {
            let p = two_prod(self.0, b.0);
            fast_two_sum(p.0, p.1 + (self.0 * b.1 + self.1 * b.0))
        }
        fn div_f64(self, b: f64) -> Dd {
            let q = self.0 / b;
            let p = two_prod(q, b);
            fast_two_sum(q, (((self.0 - p.0) - p.1) + self.1) / b)
        }
    }

    /// `(sin x, cos x)` to about 100 bits, for `|x| <` [`REDUCTION_BOUND`]:
    /// `y = x − n·π/2` in double-double with π/2 as the sum of four doubles (fdlibm's
    /// three 33-bit parts and the last tail: 152 bits, so that `n·π/2` is good to 2⁻¹³⁰
    /// and every `n·Pᵢ` is exact), then the Taylor series of `sin y` and `cos y` to
    /// `y²⁷`, `y²⁸` (truncation below 10⁻³⁰ for `|y| ≤ 0.8`) in double-double.
    fn reference(x: f64) -> (Dd, Dd) {
        let n = (x * INV_PIO2).round();
        let mut y = Dd(x, 0.0);
        for p in [PIO2_1, PIO2_2, PIO2_3, PIO2_3T] {
            y = y.add(two_prod(n, p).neg());
        }
        let y2 = y.mul(y);
        let (mut s, mut c) = (Dd(1.0, 0.0), Dd(1.0, 0.0));
        for k in (1..=14).rev() {
            let k = f64::from(k);
            s = Dd(1.0, 0.0).add(y2.mul(s).div_f64(2.0 * k * (2.0 * k + 1.0)).neg());
            c = Dd(1.0, 0.0).add(y2.mul(c).div_f64((2.0 * k - 1.0) * 2.0 * k).neg());
        }
        let s = y.mul(s);
        match (n as i64).rem_euclid(4) {
            0 => (s, c),
            1 => (c, s.neg()),
            2 => (s.neg(), c.neg()),
            _ => (c.neg(), s),
        }
    }

    /// The error of `r` from the reference `v`, in units in the last place of `v`.
    fn error(r: f64, v: Dd) -> f64 {
        let exp = ((v.0.to_bits() >> 52) & 0x7ff) as i32 - 1075;
        let ulp = 2f64.powi(exp.max(-1074));
        (((r - v.0) - v.1) / ulp).abs()
    }

    /// Over `count` arguments from `arg`: the largest ulp distance of `sin`, `cos` and
    /// both of `sin_cos` from glibc's `f64::sin`/`f64::cos`, how many arguments differ,
    /// and where they differ (and at every 16th argument) the largest errors of ours and
    /// of glibc's from [`reference`], in ulps.
    fn worst(count: usize, mut arg: impl FnMut() -> f64) -> (u64, usize, f64, f64) {
        let (mut max, mut differ, mut ours, mut glibc) = (0, 0, 0.0f64, 0.0f64);
        for i in 0..count {
            let x = arg();
            let (s, c) = sin_cos(x);
            let (s0, c0) = (x.sin(), x.cos());
            assert_eq!(
                s.to_bits(),
                sin(x).to_bits(),
                "sin and sin_cos agree at {x:e}"
            );
            assert_eq!(
                c.to_bits(),
                cos(x).to_bits(),
                "cos and sin_cos agree at {x:e}"
            );
            let d = ulps(s, s0).max(ulps(c, c0));
            if d > 0 {
                differ += 1;
            }
            max = max.max(d);
            if (d > 0 || i % 16 == 0) && x.abs() < REDUCTION_BOUND {
                let (rs, rc) = reference(x);
                ours = ours.max(error(s, rs)).max(error(c, rc));
                glibc = glibc.max(error(s0, rs)).max(error(c0, rc));
            }
        }
        (max, differ, ours, glibc)
    }

    /// Two million uniform arguments per range, `|x| < π/4`, `< 10`, `< 10³`, `< 10⁵`,
    /// below the reduction bound, and log-uniform from 2⁻³⁰ to the bound. Measured: at
    /// most one ulp from glibc's `sin`/`cos` everywhere (about 6 % of the arguments
    /// differ in `sin` or `cos`, by one ulp), and against the double-double
    /// [`reference`] at those arguments and every 16th other one a largest error of
    /// 0.78 ulp here and 0.52 ulp for glibc. Asserted: one ulp from glibc, and below
    /// 0.9 ulp from the reference (fdlibm's bound is 1 ulp). The fallback region, up to
    /// 10¹⁵, gives glibc's results exactly.
    #[test]
    fn within_one_ulp_of_glibc() {
        let mut rng = Rng(0x5EED_0008);
        let ranges = [std::f64::consts::FRAC_PI_4, 10.0, 1e3, 1e5, REDUCTION_BOUND];
        let check = |what: &str, (max, differ, ours, glibc): (u64, usize, f64, f64)| {
            eprintln!(
                "{what}: {max} ulp from glibc at most, {differ} of 2e6 differ; \
                 error {ours:.3} ulp (glibc {glibc:.3})"
            );
            assert!(max <= 1, "{what}: {max} ulp from glibc");
            assert!(ours < 0.9, "{what}: {ours} ulp from the reference");
        };
        for a in ranges {
            check(&format!("|x| < {a:e}"), worst(2_000_000, || rng.uniform(a)));
        }
        check(
            "log-uniform 2^-30 .. 2^20.6",
            worst(2_000_000, || {
                let x = rng.uniform(1.0);
                x.signum() * 2f64.powf(-30.0 + 50.6 * x.abs())
            }),
        );
        let (max, ..) = worst(200_000, || {
            let x = rng.uniform(1.0);
            x.signum() * REDUCTION_BOUND * 1e9f64.powf(x.abs())
        });
        assert_eq!(max, 0, "the fallback region is glibc's");
    }

    /// The reference itself, to 10⁻³⁰, against closed forms at the doubles nearest
    /// π/6, π/3 and π/4: with `δ` the double's distance from the exact angle (in
    /// double-double, from the four-part π/2), `sin(π/6 + δ) = 1/2 + (√3/2)·δ`,
    /// `cos(π/3 + δ) = 1/2 − (√3/2)·δ` and `sin(π/4 + δ) = cos(π/4 − δ) = (√2/2)(1 + δ)`
    /// up to `δ²/2 < 10⁻³³`; and against glibc within one ulp at 5000 arguments.
    #[test]
    fn reference_is_accurate() {
        use std::f64::consts::{FRAC_1_SQRT_2, FRAC_PI_3, FRAC_PI_4, FRAC_PI_6};
        let pio2 = [PIO2_2, PIO2_3, PIO2_3T]
            .into_iter()
            .fold(Dd(PIO2_1, 0.0), |s, p| s.add(Dd(p, 0.0)));
        let delta = |k: f64, x: f64| Dd(x, 0.0).add(pio2.div_f64(k).neg());
        let half_sqrt3 = 0.866_025_403_784_438_6;
        // √2/2 in double-double: the double and its correction (1/2 − s²)/(2s).
        let sq = two_prod(FRAC_1_SQRT_2, FRAC_1_SQRT_2);
        let sqrt2_2 = fast_two_sum(FRAC_1_SQRT_2, ((0.5 - sq.0) - sq.1) / (2.0 * FRAC_1_SQRT_2));
        let close = |v: Dd, w: Dd| {
            let d = v.add(w.neg());
            (d.0 + d.1).abs() <= 1e-30
        };
        let d6 = delta(3.0, FRAC_PI_6);
        let want = Dd(0.5, 0.0).add(Dd(half_sqrt3 * d6.0, 0.0));
        assert!(close(reference(FRAC_PI_6).0, want), "sin(π/6)");
        let d3 = delta(1.5, FRAC_PI_3);
        let want = Dd(0.5, 0.0).add(Dd(-half_sqrt3 * d3.0, 0.0));
        assert!(close(reference(FRAC_PI_3).1, want), "cos(π/3)");
        let d4 = delta(2.0, FRAC_PI_4);
        let (s, c) = reference(FRAC_PI_4);
        assert!(close(s, sqrt2_2.mul(Dd(1.0, 0.0).add(d4))), "sin(π/4)");
        assert!(
            close(c, sqrt2_2.mul(Dd(1.0, 0.0).add(d4.neg()))),
            "cos(π/4)"
        );
        let mut rng = Rng(7);
        for _ in 0..5000 {
            let x = rng.uniform(1e5);
            let (s, c) = reference(x);
            assert!(
                error(x.sin(), s) < 1.0 && error(x.cos(), c) < 1.0,
                "at {x:e}"
            );
        }
    }

    /// Arguments next to multiples of π/2 (where the reduction cancels and needs the
    /// second and third parts of π/2): the nearest doubles to kπ/2 and their
    /// neighbours, k up to 2²⁰. The results there are tiny (≈ 6·10⁻¹⁷·k) and must keep
    /// their relative accuracy: at most one ulp from glibc and below 0.9 ulp from the
    /// double-double reference.
    #[test]
    fn near_multiples_of_half_pi() {
        let (mut max, mut err) = (0, 0.0f64);
        let mut check = |x: f64| {
            let (s, c) = sin_cos(x);
            max = max.max(ulps(s, x.sin())).max(ulps(c, x.cos()));
            let (rs, rc) = reference(x);
            err = err.max(error(s, rs)).max(error(c, rc));
        };
        for k in (1..=1u64 << 20).step_by(97).chain(1..200) {
            let x = k as f64 * std::f64::consts::FRAC_PI_2;
            if x >= REDUCTION_BOUND {
                continue;
            }
            for d in -3i64..=3 {
                let y = f64::from_bits((x.to_bits() as i64 + d) as u64);
                check(y);
                check(-y);
            }
        }
        eprintln!("near kπ/2: {max} ulp from glibc, error {err:.3} ulp");
        assert!(max <= 1, "near kπ/2: {max} ulp from glibc");
        assert!(err < 0.9, "near kπ/2: {err} ulp from the reference");
    }

    /// Special values: signed zeros, tiny arguments, NaN, infinities, the bound's
    /// neighbours, π/2, π and 2π as doubles (glibc: 6.123233995736766e-17,
    /// 1.2246467991473532e-16, −2.4492935982947064e-16).
    #[test]
    fn special_values() {
        assert_eq!(sin(0.0).to_bits(), 0.0f64.to_bits());
        assert_eq!(sin(-0.0).to_bits(), (-0.0f64).to_bits(), "sin(−0) = −0");
        assert_eq!(cos(-0.0), 1.0);
        assert_eq!(sin_cos(-0.0).0.to_bits(), (-0.0f64).to_bits());
        for x in [
            1e-300,
            -1e-300,
            5e-324,
            1e-10,
            -3e-9,
            2f64.powi(-26),
            1.49e-8,
        ] {
            assert_eq!(sin(x), x.sin(), "sin({x:e})");
            assert_eq!(cos(x), x.cos(), "cos({x:e})");
        }
        for x in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            let (s, c) = sin_cos(x);
            assert!(s.is_nan() && c.is_nan(), "sin_cos({x}) is NaN");
        }
        let b = REDUCTION_BOUND;
        for x in [
            b,
            -b,
            f64::from_bits(b.to_bits() - 1),
            f64::from_bits(b.to_bits() + 1),
            1e22,
            -1e300,
            f64::MAX,
        ] {
            assert!(
                ulps(sin(x), x.sin()) <= 1 && ulps(cos(x), x.cos()) <= 1,
                "{x:e}"
            );
        }
        use std::f64::consts::{FRAC_PI_2, PI, TAU};
        assert_eq!(cos(FRAC_PI_2), 6.123_233_995_736_766e-17);
        assert_eq!(sin(PI), 1.224_646_799_147_353_2e-16);
        assert_eq!(sin(TAU), -2.449_293_598_294_706_4e-16);
        assert_eq!(sin(FRAC_PI_2), 1.0);
        assert_eq!(cos(PI), -1.0);
    }

    /// `sin²x + cos²x = 1` within 2·2⁻⁵³ + the two squares' roundings (3 ulp of 1),
    /// `sin(−x) = −sin x`, `cos(−x) = cos x` exactly, and `sin(x + π/2) = cos x` to
    /// the rounding of the shifted argument (2⁻⁵³·|x| absolute, plus 2 ulp of 1).
    #[test]
    fn identities() {
        let mut rng = Rng(0x1D_E711);
        for _ in 0..200_000 {
            let x = rng.uniform(1e4);
            let (s, c) = sin_cos(x);
            assert!(
                (s * s + c * c - 1.0).abs() <= 3.0 * f64::EPSILON,
                "at {x:e}"
            );
            assert_eq!(sin(-x).to_bits(), (-s).to_bits(), "odd at {x:e}");
            assert_eq!(cos(-x).to_bits(), c.to_bits(), "even at {x:e}");
            let shifted = x + std::f64::consts::FRAC_PI_2;
            let tol = 2.0 * f64::EPSILON + f64::EPSILON * shifted.abs();
            assert!((sin(shifted) - c).abs() <= tol, "shift at {x:e}");
        }
    }

    /// Arguments for the pair tests: every range of the reduction, multiples of π/2
    /// and their neighbours (the cancelling reductions), and the values outside the
    /// fast path.
    fn pair_arguments() -> Vec<f64> {
        let mut rng = Rng(0x5EED_0002);
        let mut args = vec![
            0.0,
            -0.0,
            1e-300,
            -3e-9,
            f64::MIN_POSITIVE,
            f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            REDUCTION_BOUND,
            -REDUCTION_BOUND * 1.5,
            1e300,
        ];
        for k in -200..=200 {
            let m = f64::from(k) * std::f64::consts::FRAC_PI_2;
            args.extend([m, m.next_up(), m.next_down(), m + 1e-9, m - 3e-6]);
        }
        for a in [std::f64::consts::FRAC_PI_4, 1.0, 20.0, 1e3, 1e6] {
            args.extend((0..40_000).map(|_| rng.uniform(a)));
        }
        args
    }

    /// `sin_cos2` (and its portable pass, the SSE2 pass's reference) is bitwise two
    /// calls of `sin_cos`, whichever lane holds which argument.
    #[test]
    fn pairs_are_two_calls_to_the_bit() {
        let args = pair_arguments();
        let bits =
            |((s0, c0), (s1, c1)): ((f64, f64), (f64, f64))| [s0, c0, s1, c1].map(f64::to_bits);
        let mut checked = 0;
        // Each argument beside its neighbour in the list and beside one far away, in
        // both lanes.
        let n = args.len();
        for i in 0..n {
            for j in [(i + 1) % n, (i * 7919 + 13) % n] {
                let (a, b) = (args[i], args[j]);
                let want = bits((sin_cos(a), sin_cos(b)));
                assert_eq!(bits(sin_cos2(a, b)), want, "sin_cos2({a:e}, {b:e})");
                assert_eq!(
                    bits(lanes::sin_cos2(a, b)),
                    want,
                    "portable sin_cos2({a:e}, {b:e})"
                );
                checked += 1;
            }
        }
        assert!(checked > 400_000);
    }
}
