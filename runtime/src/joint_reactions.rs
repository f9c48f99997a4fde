//! Reactions per joint: the force and torque a joint of [`Info::joints`] transmits,
//! in the global frame and in the axes of the joint's first frame.
//!
//! Input: a [`Mechanism`] with frames and joints, a state $(t, q)$ and the multipliers
//! $\lambda$ there (from [`Reactions`]: [`Reactions::joints`]). Output:
//! [`JointReactions`], one [`JointReaction`] per joint.
//!
//! **The mapping.** A joint's rows $R$ (its holonomic and non-holonomic constraints)
//! push on the system with the generalized force $Q_R = -J_R^\mathsf{T}\lambda_R$
//! (docs/theory.md §augmented; [`Reactions::constraint_force`] summed over the rows). The joint
//! transmits a wrench: a force $F$ acting on its first frame $a$ at the frame's origin
//! $o_a$ and a torque $T$ on $a$, and by Newton's third law $-F$ at the same point and
//! $-T$ on its second frame $b$ (the ground when absent). By virtual power, that wrench
//! has the generalized force
//! $$Q(F, T) = (J_v^a - J_{v,o_a}^b)^\mathsf{T} F + (J_\omega^a - J_\omega^b)^\mathsf{T} T,
//! \qquad J_{v,o_a}^b = J_v^b - [o_a - o_b]_\times J_\omega^b,$$
//! with $J_v^f = \partial o_f/\partial q$ the translational and $J_\omega^f$ (from
//! $\tilde\omega = \dot A A^\mathsf{T}$) the rotational velocity Jacobians of frame $f$.
//! $(F, T)$ is the least-squares solution of $Q(F, T) = Q_R$ (3 unknowns $F_x, F_y,
//! T_z$ when both frames are planar, else 6), and the relative residual
//! $\lVert Q(F, T) - Q_R\rVert_2 / \lVert Q_R\rVert_2$ is reported: it is at round-off
//! and difference level whenever the joint's rows depend on the poses of its two frames
//! only (every joint kind of the body level), and shows when they do not.
//!
//! **Euler parameters.** A frame oriented by Euler parameters $\theta$ has
//! $\partial A/\partial\theta$ with a part that scales $A$ (along $\theta$), which no
//! wrench produces; the rows' force along it is carried by the normalization
//! $\theta^\mathsf{T}\theta - 1 = 0$. The gradient of the normalization of every such
//! frame on the two frames' parent chains is therefore an extra column of the fit, whose
//! coefficient is not reported.
//!
//! **Velocity Jacobians by differences.** The Jacobians are the derivatives of
//! [`Mechanism::frame_poses`] by the fourth-order central difference
//! $f' \approx [f(q-2h) - 8f(q-h) + 8f(q+h) - f(q+2h)]/(12h)$ with
//! $h = \varepsilon^{1/5} \approx 7.4\cdot10^{-4}$ in the coordinate's unit: truncation
//! $h^4|f^{(5)}|/30$ plus round-off about $1.5\,\varepsilon|f|/h$, so about $10^{-12}$
//! relative for poses that vary on the scale of one unit of the coordinates (radians,
//! and lengths comparable to the model's). The error enters the reported residual.
//! Measured: residuals below $10^{-10}$ on every joint kind of the test models
//! (`tests/src/bodies/reactions.rs`).
//!
//! **Determinacy.** When the two frames' motions cannot produce every wrench component
//! (a frame moved by fewer coordinates than it has freedoms, or a second frame given
//! relative to the first), the components they cannot produce are not determined by the
//! multipliers: [`JointReaction::rank`] says how many are, and the others are set to
//! zero (basic solution of a column-pivoted QR).
//!
//! Drivers have no frames (`[None, None]`): their reaction is reported as the
//! generalized force only ([`JointReactions::generalized_force`]).

use crate::reactions::Reactions;
use crate::workspace::scatter_row_major;
use crate::{Info, JointKind, Mechanism};

/// A force and a torque acting on a frame, about its origin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wrench {
    /// The force, global axes.
    pub force: [f64; 3],
    /// The torque about the frame's origin, global axes.
    pub torque: [f64; 3],
    /// The force in the frame's axes ($A^\mathsf{T} F$).
    pub force_body: [f64; 3],
    /// The torque in the frame's axes ($A^\mathsf{T} T$).
    pub torque_body: [f64; 3],
}

/// What one joint transmits at one state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointReaction {
    /// The joint's name.
    pub name: &'static str,
    /// Its index in [`Info::joints`].
    pub index: usize,
    /// What it is.
    pub kind: JointKind,
    /// The wrench on its first frame (about that frame's origin; the ground's origin
    /// when the first frame is the ground). `None` for a joint without frames.
    pub first: Option<Wrench>,
    /// The wrench on its second frame, about that frame's origin: $-F$ at the first
    /// frame's origin and $-T$ (Newton's third law). `None` for a joint without frames.
    pub second: Option<Wrench>,
    /// $\lVert Q(F, T) - Q_R\rVert_2 / \lVert Q_R\rVert_2$ (the absolute norm when
    /// $Q_R = 0$).
    pub residual: f64,
    /// Wrench components the fit determines.
    pub rank: usize,
    /// Wrench components fitted: 3 ($F_x, F_y, T_z$) for planar frames, else 6.
    pub components: usize,
}

/// The wrench of a joint fitted to its generalized force, with scratch.
#[derive(Clone, Debug)]
pub struct JointReactions {
    info: &'static Info,
    /// Time of the state.
    pub t: f64,
    reactions: Vec<JointReaction>,
    /// Per joint, its generalized force $Q_R$ (length $n$ each).
    forces: Vec<f64>,
    poses: Vec<f64>,
    /// $\partial(\text{pose})/\partial q_i$: `12 · frames` values per coordinate.
    dposes: Vec<f64>,
    shifted: [Vec<f64>; 4],
    q: Vec<f64>,
    cq: Vec<f64>,
    g: Vec<f64>,
    cq_dense: Vec<f64>,
    /// The joint of each constraint row, holonomic first.
    row_joint: Vec<Option<usize>>,
    a: Vec<f64>,
    rhs: Vec<f64>,
}

/// Step of the pose differences, $\varepsilon^{1/5}$.
fn step() -> f64 {
    f64::EPSILON.powf(0.2)
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}

impl JointReactions {
    /// Zeroed joint reactions for the model described by `info`.
    #[must_use]
    pub fn new(info: &'static Info) -> Self {
        let (n, nf) = (info.nq(), info.frames.len());
        let reactions = info
            .joints
            .iter()
            .enumerate()
            .map(|(index, j)| JointReaction {
                name: j.name,
                index,
                kind: j.kind,
                first: None,
                second: None,
                residual: 0.0,
                rank: 0,
                components: 0,
            })
            .collect();
        let mut row_joint = vec![None; info.nh() + info.nnh()];
        for (j, joint) in info.joints.iter().enumerate() {
            let (h0, hl) = (joint.holonomic.0 as usize, joint.holonomic.1 as usize);
            let (n0, nl) = (joint.nonholonomic.0 as usize, joint.nonholonomic.1 as usize);
            for k in (h0..h0 + hl).chain(info.nh() + n0..info.nh() + n0 + nl) {
                row_joint[k] = Some(j);
            }
        }
        Self {
            info,
            t: 0.0,
            reactions,
            forces: vec![0.0; info.joints.len() * n],
            poses: vec![0.0; 12 * nf],
            dposes: vec![0.0; 12 * nf * n],
            shifted: std::array::from_fn(|_| vec![0.0; 12 * nf]),
            q: vec![0.0; n],
            cq: vec![0.0; info.holonomic_pattern.len()],
            g: vec![0.0; info.nonholonomic_pattern.len()],
            row_joint,
            cq_dense: vec![0.0; info.nh() * n],
            a: Vec::with_capacity(n * (6 + 2 * nf)),
            rhs: vec![0.0; n],
        }
    }

    /// The model description.
    #[must_use]
    pub fn info(&self) -> &'static Info {
        self.info
    }

    /// The reactions of all joints, in the order of [`Info::joints`].
    pub fn iter(&self) -> impl Iterator<Item = &JointReaction> + '_ {
        self.reactions.iter()
    }

    /// The reaction of the joint called `name`.
    #[must_use]
    pub fn get(&self, name: &str) -> Option<&JointReaction> {
        self.reactions.iter().find(|r| r.name == name)
    }

    /// The generalized force $Q_R = -J_R^\mathsf{T}\lambda_R$ of joint `index` (its rows
    /// only), length $n$.
    ///
    /// # Panics
    /// When `index` is not below the number of joints.
    #[must_use]
    pub fn generalized_force(&self, index: usize) -> &[f64] {
        let n = self.info.nq();
        &self.forces[index * n..(index + 1) * n]
    }

    /// Origin and rotation (row-major) of frame `f`, or of the ground.
    fn pose(&self, f: Option<u32>) -> ([f64; 3], [f64; 9]) {
        match f {
            Some(f) => {
                let p = &self.poses[12 * f as usize..12 * f as usize + 12];
                ([p[0], p[1], p[2]], std::array::from_fn(|k| p[3 + k]))
            }
            None => ([0.0; 3], [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]),
        }
    }

    /// `(J_v[:, i], J_ω[:, i])` of frame `f` (zero for the ground).
    fn jacobian_column(&self, f: Option<u32>, i: usize) -> ([f64; 3], [f64; 3]) {
        let Some(f) = f else {
            return ([0.0; 3], [0.0; 3]);
        };
        let nf = self.info.frames.len();
        let f = f as usize;
        let d = &self.dposes[12 * nf * i + 12 * f..12 * nf * i + 12 * f + 12];
        let a = &self.poses[12 * f + 3..12 * f + 12];
        // W = (∂A/∂q_i) Aᵀ; ω_i is the axial vector of its skew part.
        let w = |r: usize, c: usize| (0..3).map(|k| d[3 + 3 * r + k] * a[3 * c + k]).sum::<f64>();
        let omega = [
            0.5 * (w(2, 1) - w(1, 2)),
            0.5 * (w(0, 2) - w(2, 0)),
            0.5 * (w(1, 0) - w(0, 1)),
        ];
        ([d[0], d[1], d[2]], omega)
    }

    /// The joint reactions at $(t, q)$ for the multipliers `lambda`
    /// ($[\lambda_h; \lambda_{nh}]$, sign of docs/theory.md §sign, as in [`Reactions`]).
    ///
    /// Evaluates `frame_poses` $1 + 4n$ times and the holonomic Jacobian once (not a
    /// per-step path: the fit allocates a few small vectors per joint).
    ///
    /// # Panics
    /// When `q` does not have length $n$ or `lambda` length $m_h + m_{nh}$.
    pub fn evaluate<M: Mechanism + ?Sized>(&mut self, mech: &M, t: f64, q: &[f64], lambda: &[f64]) {
        let info = self.info;
        let (n, mh, nf) = (info.nq(), info.nh(), info.frames.len());
        assert_eq!(q.len(), n, "q has length n");
        assert_eq!(lambda.len(), mh + info.nnh(), "lambda has length m");
        self.t = t;
        // Generalized force of each joint's rows, -J_Rᵀ λ_R.
        self.forces.fill(0.0);
        mech.holonomic_jacobian(t, q, &mut self.cq);
        mech.nonholonomic_matrix(t, q, &mut self.g);
        let entries = info
            .holonomic_pattern
            .iter()
            .zip(&self.cq)
            .map(|(&(r, c), v)| (r as usize, c as usize, v))
            .chain(
                info.nonholonomic_pattern
                    .iter()
                    .zip(&self.g)
                    .map(|(&(r, c), v)| (mh + r as usize, c as usize, v)),
            );
        for (r, c, v) in entries {
            if let Some(j) = self.row_joint[r] {
                self.forces[j * n + c] -= v * lambda[r];
            }
        }
        if nf == 0 {
            return;
        }
        // Poses and their derivatives.
        mech.frame_poses(t, q, &mut self.poses);
        let h = step();
        self.q.copy_from_slice(q);
        for (i, &qi) in q.iter().enumerate() {
            for (s, buf) in [-2.0, -1.0, 1.0, 2.0].iter().zip(self.shifted.iter_mut()) {
                self.q[i] = qi + s * h;
                mech.frame_poses(t, &self.q, buf);
            }
            self.q[i] = qi;
            let [m2, m1, p1, p2] = &self.shifted;
            let d = &mut self.dposes[12 * nf * i..12 * nf * (i + 1)];
            for (k, dk) in d.iter_mut().enumerate() {
                *dk = ((m2[k] - p2[k]) + 8.0 * (p1[k] - m1[k])) / (12.0 * h);
            }
        }
        if mh > 0 && info.frames.iter().any(|f| f.normalization.is_some()) {
            scatter_row_major(info.holonomic_pattern, &self.cq, n, &mut self.cq_dense);
        }
        for j in 0..info.joints.len() {
            self.fit(j);
        }
    }

    /// The normalization rows of the frames on the parent chains of `frames`.
    fn normalizations(&self, frames: [Option<u32>; 2]) -> Vec<usize> {
        let mut rows = Vec::new();
        for mut f in frames {
            while let Some(k) = f {
                let frame = &self.info.frames[k as usize];
                if let Some(r) = frame.normalization {
                    if !rows.contains(&(r as usize)) {
                        rows.push(r as usize);
                    }
                }
                f = frame.parent;
            }
        }
        rows
    }

    #[allow(clippy::many_single_char_names)]
    fn fit(&mut self, j: usize) {
        let info = self.info;
        let n = info.nq();
        let joint = &info.joints[j];
        let [fa, fb] = joint.frames;
        if fa.is_none() && fb.is_none() {
            let r = &mut self.reactions[j];
            r.first = None;
            r.second = None;
            r.rank = 0;
            r.components = 0;
            r.residual = 0.0;
            return;
        }
        let planar = joint
            .frames
            .iter()
            .all(|f| f.is_none_or(|f| info.frames[f as usize].planar));
        // (F index, T index) of the unknowns: planar Fx, Fy, Tz.
        let (fcomp, tcomp): (&[usize], &[usize]) = if planar {
            (&[0, 1], &[2])
        } else {
            (&[0, 1, 2], &[0, 1, 2])
        };
        let c = fcomp.len() + tcomp.len();
        let extra = self.normalizations(joint.frames);
        let p = c + extra.len();
        let (oa, aa) = self.pose(fa);
        let (ob, ab) = self.pose(fb);
        let dab = [oa[0] - ob[0], oa[1] - ob[1], oa[2] - ob[2]];
        // A, column-major n × p.
        let mut a = std::mem::take(&mut self.a);
        a.clear();
        a.resize(n * p, 0.0);
        for i in 0..n {
            let (va, wa) = self.jacobian_column(fa, i);
            let (vb, wb) = self.jacobian_column(fb, i);
            let wxd = cross(wb, dab);
            for (col, &k) in fcomp.iter().enumerate() {
                a[col * n + i] = va[k] - (vb[k] + wxd[k]);
            }
            for (col, &k) in tcomp.iter().enumerate() {
                a[(fcomp.len() + col) * n + i] = wa[k] - wb[k];
            }
            for (col, &r) in extra.iter().enumerate() {
                a[(c + col) * n + i] = self.cq_dense[r * n + i];
            }
        }
        let qr = &self.forces[j * n..(j + 1) * n];
        self.rhs.copy_from_slice(qr);
        let mut work = a.clone();
        let (x, rank) = least_squares(&mut work, n, p, &mut self.rhs);
        // Residual from the unfactored columns.
        let mut res2 = 0.0;
        let mut norm2 = 0.0;
        for i in 0..n {
            let fitted: f64 = (0..p).map(|k| a[k * n + i] * x[k]).sum();
            res2 += (fitted - qr[i]).powi(2);
            norm2 += qr[i] * qr[i];
        }
        self.a = a;
        let residual = if norm2 > 0.0 {
            (res2 / norm2).sqrt()
        } else {
            res2.sqrt()
        };
        let mut force = [0.0; 3];
        let mut torque = [0.0; 3];
        for (col, &k) in fcomp.iter().enumerate() {
            force[k] = x[col];
        }
        for (col, &k) in tcomp.iter().enumerate() {
            torque[k] = x[fcomp.len() + col];
        }
        let body = |m: &[f64; 9], v: [f64; 3]| -> [f64; 3] {
            std::array::from_fn(|c| (0..3).map(|r| m[3 * r + c] * v[r]).sum())
        };
        let wrench = |m: &[f64; 9], force: [f64; 3], torque: [f64; 3]| Wrench {
            force,
            torque,
            force_body: body(m, force),
            torque_body: body(m, torque),
        };
        let dxf = cross(dab, force);
        let f2 = force.map(|v| -v);
        let t2: [f64; 3] = std::array::from_fn(|k| -torque[k] - dxf[k]);
        let r = &mut self.reactions[j];
        r.first = Some(wrench(&aa, force, torque));
        r.second = Some(wrench(&ab, f2, t2));
        r.residual = residual;
        r.rank = rank.min(c);
        r.components = c;
    }
}

/// Least squares $\min\lVert A x - b\rVert_2$ for column-major `a` ($n \times p$, $p$
/// small) by Householder QR with column pivoting on equilibrated columns; columns whose
/// pivot falls below $10^{-9}$ of the first are not used (their unknowns are zero).
/// Returns $x$ and the rank. Overwrites `a` and `b`.
fn least_squares(a: &mut [f64], n: usize, p: usize, b: &mut [f64]) -> (Vec<f64>, usize) {
    let mut scale = vec![1.0; p];
    for (k, s) in scale.iter_mut().enumerate() {
        let m = a[k * n..(k + 1) * n]
            .iter()
            .fold(0.0_f64, |m, v| m.max(v.abs()));
        if m > 0.0 {
            *s = m;
            for v in &mut a[k * n..(k + 1) * n] {
                *v /= m;
            }
        }
    }
    let mut perm: Vec<usize> = (0..p).collect();
    let mut norms: Vec<f64> = (0..p)
        .map(|k| a[k * n..(k + 1) * n].iter().map(|v| v * v).sum())
        .collect();
    let mut rank = 0;
    let mut first = 0.0;
    let mut diag = vec![0.0; p];
    for k in 0..p.min(n) {
        // Pivot: the remaining column of largest norm.
        let (best, &bn) = norms[k..]
            .iter()
            .enumerate()
            .max_by(|x, y| x.1.total_cmp(y.1))
            .map(|(i, v)| (i + k, v))
            .expect("non-empty");
        if k == 0 {
            first = bn.sqrt();
        }
        // A NaN norm stops too.
        if bn.sqrt().partial_cmp(&(1e-9 * first)) != Some(std::cmp::Ordering::Greater)
            || first == 0.0
        {
            break;
        }
        if best != k {
            for i in 0..n {
                a.swap(k * n + i, best * n + i);
            }
            norms.swap(k, best);
            perm.swap(k, best);
        }
        // Householder reflector for column k below row k.
        let col = &mut a[k * n..(k + 1) * n];
        let alpha = col[k..].iter().map(|v| v * v).sum::<f64>().sqrt();
        let alpha = if col[k] > 0.0 { -alpha } else { alpha };
        col[k] -= alpha;
        let vnorm2: f64 = col[k..].iter().map(|v| v * v).sum();
        diag[k] = alpha;
        if vnorm2 > 0.0 {
            let v: Vec<f64> = col[k..].to_vec();
            for c in k + 1..p {
                let cc = &mut a[c * n..(c + 1) * n];
                let s = 2.0 * v.iter().zip(&cc[k..]).map(|(x, y)| x * y).sum::<f64>() / vnorm2;
                for (y, x) in cc[k..].iter_mut().zip(&v) {
                    *y -= s * x;
                }
            }
            let s = 2.0 * v.iter().zip(&b[k..]).map(|(x, y)| x * y).sum::<f64>() / vnorm2;
            for (y, x) in b[k..].iter_mut().zip(&v) {
                *y -= s * x;
            }
        }
        for c in k + 1..p {
            norms[c] = a[c * n + k + 1..(c + 1) * n].iter().map(|v| v * v).sum();
        }
        rank = k + 1;
    }
    // Back substitution with R (diagonal in `diag`, above it in `a`).
    let mut z = vec![0.0; p];
    for k in (0..rank).rev() {
        let s: f64 = (k + 1..rank).map(|c| a[c * n + k] * z[c]).sum();
        z[k] = (b[k] - s) / diag[k];
    }
    let mut x = vec![0.0; p];
    for k in 0..p {
        x[perm[k]] = z[k] / scale[perm[k]];
    }
    (x, rank)
}

impl Reactions {
    /// The reactions per joint at `q` (the state these reactions were evaluated at):
    /// see [`JointReactions`].
    #[must_use]
    pub fn joints<M: Mechanism + ?Sized>(&self, mech: &M, q: &[f64]) -> JointReactions {
        let mut out = JointReactions::new(self.info());
        out.evaluate(mech, self.t, q, &self.lambda);
        out
    }
}
