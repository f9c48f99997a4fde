//! Two-node Euler–Bernoulli beam elements in their element frame: shape matrices
//! (docs/theory.md E18, E20), stiffness matrices (E19, §beam-elements) and the quadrature that
//! integrates their shape integrals exactly.
//!
//! Input: the element length $l$, its [`Section`] and a material point
//! $(\xi, \eta, \zeta) = (x, y, z)/l$. Output: $S$ (row-major, `d × 2·dofs`) and $K_e$
//! (row-major, `2·dofs × 2·dofs`). Every integrand of the shape integrals (E10) is a
//! polynomial of degree at most 6 in $\xi$ and at most 2 in $(y, z)$, so the
//! 4-point Gauss–Legendre rule along the axis (exact to degree 7) times the 5-point
//! section rule of `section_points` (exact for the section's moments up to degree 2)
//! integrates them exactly.

use super::Section;

/// Gauss–Legendre points and weights on $[0, 1]$, 4 points (exact to degree 7).
pub(crate) const GAUSS_4: [(f64, f64); 4] = {
    // Nodes ±√(3/7 ∓ 2/7 √(6/5)) and weights (18 ± √30)/36 on [−1, 1], mapped to [0, 1].
    const A: f64 = 0.339_981_043_584_856_26;
    const B: f64 = 0.861_136_311_594_052_6;
    const WA: f64 = 0.652_145_154_862_546_1;
    const WB: f64 = 0.347_854_845_137_453_9;
    [
        (0.5 * (1.0 - B), 0.5 * WB),
        (0.5 * (1.0 - A), 0.5 * WA),
        (0.5 * (1.0 + A), 0.5 * WA),
        (0.5 * (1.0 + B), 0.5 * WB),
    ]
};

/// Points `(y, z, w)` of the cross-section with mass fractions `w` summing to 1, such
/// that $\sum w\,f(y, z)\,\rho A = \int_A \rho f\,dA$ for every polynomial $f$ of degree
/// ≤ 2 on a section with centroidal principal axes: $\int\rho\,dA = \rho A$,
/// $\int\rho y\,dA = \int\rho z\,dA = \int\rho yz\,dA = 0$,
/// $\int\rho y^2\,dA = \rho I_z$, $\int\rho z^2\,dA = \rho I_y$.
///
/// Half the mass sits on the axis and an eighth at each of $(\pm r_y, 0)$,
/// $(0, \pm r_z)$ with $r_y^2 = 4\rho I_z/\rho A$, $r_z^2 = 4\rho I_y/\rho A$. A
/// centre-line section (no rotary inertia) is the single point on the axis.
pub(crate) fn section_points(section: &Section) -> Vec<(f64, f64, f64)> {
    if section.rho_iy == 0.0 && section.rho_iz == 0.0 {
        return vec![(0.0, 0.0, 1.0)];
    }
    let ry = 2.0 * (section.rho_iz / section.rho_a).sqrt();
    let rz = 2.0 * (section.rho_iy / section.rho_a).sqrt();
    vec![
        (0.0, 0.0, 0.5),
        (ry, 0.0, 0.125),
        (-ry, 0.0, 0.125),
        (0.0, rz, 0.125),
        (0.0, -rz, 0.125),
    ]
}

/// Columns of the planar element: `[u1, v1, θ1, u2, v2, θ2]`.
pub(crate) const PLANAR_DOFS: usize = 6;
/// Columns of the spatial element: `[ux1, uy1, uz1, θx1, θy1, θz1, ux2, …, θz2]`.
pub(crate) const SPATIAL_DOFS: usize = 12;

/// The planar shape matrix $S(\xi)$ of E18, row-major 2 × 6.
#[must_use]
pub(crate) fn planar_shape(l: f64, xi: f64) -> [f64; 12] {
    let x2 = xi * xi;
    let x3 = x2 * xi;
    [
        1.0 - xi,
        0.0,
        0.0,
        xi,
        0.0,
        0.0,
        0.0,
        1.0 - 3.0 * x2 + 2.0 * x3,
        l * (xi - 2.0 * x2 + x3),
        0.0,
        3.0 * x2 - 2.0 * x3,
        l * (x3 - x2),
    ]
}

/// The spatial shape matrix $S(\xi, \eta, \zeta)$ of E20, row-major 3 × 12, at the
/// section point $(y, z)$ (so $\eta = y/l$, $\zeta = z/l$ and $l\eta = y$).
#[must_use]
pub(crate) fn spatial_shape(l: f64, xi: f64, y: f64, z: f64) -> [f64; 36] {
    let x2 = xi * xi;
    let x3 = x2 * xi;
    let (eta, zeta) = (y / l, z / l);
    let b = 6.0 * (xi - x2); // −H1′ = H3′ (per unit ξ)
    let r1 = 1.0 - 4.0 * xi + 3.0 * x2; // H2′
    let r2 = 3.0 * x2 - 2.0 * xi; // H4′
    let h1 = 1.0 - 3.0 * x2 + 2.0 * x3;
    let h2 = l * (xi - 2.0 * x2 + x3);
    let h3 = 3.0 * x2 - 2.0 * x3;
    let h4 = l * (x3 - x2);
    [
        // row 1: u_x = u0 − y v′ − z w′
        1.0 - xi,
        eta * b,
        zeta * b,
        0.0,
        z * r1,
        -y * r1,
        xi,
        -eta * b,
        -zeta * b,
        0.0,
        z * r2,
        -y * r2,
        // row 2: u_y = v − z φ
        0.0,
        h1,
        0.0,
        -z * (1.0 - xi),
        0.0,
        h2,
        0.0,
        h3,
        0.0,
        -z * xi,
        0.0,
        h4,
        // row 3: u_z = w + y φ
        0.0,
        0.0,
        h1,
        y * (1.0 - xi),
        -h2,
        0.0,
        0.0,
        0.0,
        h3,
        y * xi,
        -h4,
        0.0,
    ]
}

/// The planar stiffness matrix of E19, row-major 6 × 6.
#[must_use]
pub(crate) fn planar_stiffness(l: f64, section: &Section) -> Vec<f64> {
    let a = section.ea / l;
    let ei = section.ei_z;
    let (b12, b6, b4, b2) = (
        12.0 * ei / l.powi(3),
        6.0 * ei / l.powi(2),
        4.0 * ei / l,
        2.0 * ei / l,
    );
    #[rustfmt::skip]
    let k = vec![
         a,   0.0,  0.0, -a,   0.0,  0.0,
        0.0,  b12,  b6,  0.0, -b12,  b6,
        0.0,  b6,   b4,  0.0, -b6,   b2,
        -a,   0.0,  0.0,  a,   0.0,  0.0,
        0.0, -b12, -b6,  0.0,  b12, -b6,
        0.0,  b6,   b2,  0.0, -b6,   b4,
    ];
    k
}

/// The spatial stiffness matrix of docs/theory.md §beam-elements, row-major 12 × 12, from
/// $U_e = \tfrac12\int_0^l (EA u_0'^2 + EI_z v''^2 + EI_y w''^2 + GJ\varphi'^2)\,dx$.
#[must_use]
pub(crate) fn spatial_stiffness(l: f64, section: &Section) -> Vec<f64> {
    let n = SPATIAL_DOFS;
    let mut k = vec![0.0; n * n];
    // Upper-triangle entries (1-based, as in the table), mirrored below.
    let mut set = |i: usize, j: usize, v: f64| {
        k[(i - 1) * n + (j - 1)] = v;
        k[(j - 1) * n + (i - 1)] = v;
    };
    let (l2, l3) = (l * l, l * l * l);
    let (ea, eiy, eiz, gj) = (section.ea, section.ei_y, section.ei_z, section.gj);
    for (i, j, s) in [(1, 1, 1.0), (7, 7, 1.0), (1, 7, -1.0)] {
        set(i, j, s * ea / l);
    }
    for (i, j, s) in [(2, 2, 1.0), (8, 8, 1.0), (2, 8, -1.0)] {
        set(i, j, s * 12.0 * eiz / l3);
    }
    for (i, j, s) in [(2, 6, 1.0), (2, 12, 1.0), (6, 8, -1.0), (8, 12, -1.0)] {
        set(i, j, s * 6.0 * eiz / l2);
    }
    for (i, j, s) in [(3, 3, 1.0), (9, 9, 1.0), (3, 9, -1.0)] {
        set(i, j, s * 12.0 * eiy / l3);
    }
    for (i, j, s) in [(3, 5, 1.0), (3, 11, 1.0), (5, 9, -1.0), (9, 11, -1.0)] {
        set(i, j, -s * 6.0 * eiy / l2);
    }
    for (i, j, s) in [(4, 4, 1.0), (10, 10, 1.0), (4, 10, -1.0)] {
        set(i, j, s * gj / l);
    }
    set(5, 5, 4.0 * eiy / l);
    set(11, 11, 4.0 * eiy / l);
    set(5, 11, 2.0 * eiy / l);
    set(6, 6, 4.0 * eiz / l);
    set(12, 12, 4.0 * eiz / l);
    set(6, 12, 2.0 * eiz / l);
    k
}
