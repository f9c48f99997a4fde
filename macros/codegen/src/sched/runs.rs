//! Contractions of run-time data with coordinates inside a sum.
//!
//! Input: the terms of one canonical sum and the data slots. Output: the runs of terms
//! `c · D[d₀ + k s] · x_{i₀ + k}`, `k = 0 … L−1`, `L ≥ MIN_RUN` (`x` the coordinates or
//! the velocities, one slot, one coefficient `c`), and the terms left over. Which
//! strides to look for comes from the terms themselves: the differences between the
//! data indices of terms of neighbouring coordinates (row-major invariant blocks give
//! 1 along a row and the number of columns down a column).

use std::collections::BTreeMap;
use std::ops::Range;

use crate::sym::{ExprId, Graph, Node, Var};

/// Shortest contraction kept as a loop: below it the unrolled products are as short as
/// the loop and keep the generated code of small bodies (4 modes) as it was.
pub const MIN_RUN: usize = 8;

/// `coef · Σ_{k < len} D[data + k·stride] · x[first + k]`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Run {
    pub coef: f64,
    /// `Var::Q(i₀)` or `Var::Qd(i₀)`: the first coordinate or velocity.
    pub first: Var,
    pub len: u32,
    /// The `Var::Data` index of the first entry.
    pub data: u32,
    pub stride: u32,
}

/// The contraction terms of one coefficient and kind of variable: (variable index,
/// data index, index of the term in the sum).
type Group = Vec<(u32, u32, usize)>;

/// A term `c · D[d] · x_i` as `(c, velocity?, i, d)`.
fn contraction_term(g: &Graph, t: ExprId) -> Option<(f64, bool, u32, u32)> {
    let Node::Mul(f) = g.node(t) else {
        return None;
    };
    if f.len() > 3 {
        return None;
    }
    let (mut c, mut x, mut d) = (None, None, None);
    for &a in f.iter() {
        match g.node(a) {
            Node::Const(b) if c.is_none() => c = Some(f64::from_bits(*b)),
            Node::Var(Var::Data(k)) if d.is_none() => d = Some(*k),
            Node::Var(Var::Q(i)) if x.is_none() => x = Some((false, *i)),
            Node::Var(Var::Qd(i)) if x.is_none() => x = Some((true, *i)),
            _ => return None,
        }
    }
    let ((vel, i), d) = (x?, d?);
    Some((c.unwrap_or(1.0), vel, i, d))
}

/// The runs among `terms` and the terms left over (in their order); `None` without runs.
pub fn find(g: &Graph, terms: &[ExprId], slots: &[Range<u32>]) -> Option<(Vec<Run>, Vec<ExprId>)> {
    if terms.len() < MIN_RUN {
        return None;
    }
    // Groups by coefficient and kind of variable: (var index, data index, term index).
    let mut groups: BTreeMap<(u64, bool), Group> = BTreeMap::new();
    for (k, &t) in terms.iter().enumerate() {
        if let Some((c, vel, i, d)) = contraction_term(g, t) {
            groups
                .entry((c.to_bits(), vel))
                .or_default()
                .push((i, d, k));
        }
    }
    let mut used = vec![false; terms.len()];
    let mut runs = Vec::new();
    for ((c, vel), members) in &groups {
        if members.len() < MIN_RUN {
            continue;
        }
        let mut by_var: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
        for &(i, d, _) in members {
            by_var.entry(i).or_default().push(d);
        }
        let mut counts: BTreeMap<u32, usize> = BTreeMap::new();
        for (&i, ds) in &by_var {
            let Some(next) = i.checked_add(1).and_then(|j| by_var.get(&j)) else {
                continue;
            };
            for &d1 in ds {
                for &d2 in next {
                    if d2 > d1 {
                        *counts.entry(d2 - d1).or_default() += 1;
                    }
                }
            }
        }
        let mut strides: Vec<(usize, u32)> = counts
            .into_iter()
            .filter(|&(_, n)| n + 1 >= MIN_RUN)
            .map(|(s, n)| (n, s))
            .collect();
        strides.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)));
        for (_, s) in strides {
            // Terms on one line `d = base + s·i`, by base then variable.
            let mut lines: BTreeMap<i64, BTreeMap<u32, (u32, usize)>> = BTreeMap::new();
            for &(i, d, k) in members {
                if !used[k] {
                    let base = i64::from(d) - i64::from(s) * i64::from(i);
                    lines.entry(base).or_default().entry(i).or_insert((d, k));
                }
            }
            for line in lines.values() {
                let mut seq: Vec<(u32, u32, usize)> = Vec::new();
                let mut flush = |seq: &mut Vec<(u32, u32, usize)>| {
                    if seq.len() >= MIN_RUN {
                        let (i0, d0, _) = seq[0];
                        let d1 = seq[seq.len() - 1].1;
                        if slots.iter().any(|r| r.contains(&d0) && r.contains(&d1)) {
                            runs.push(Run {
                                coef: f64::from_bits(*c),
                                first: if *vel { Var::Qd(i0) } else { Var::Q(i0) },
                                len: u32::try_from(seq.len()).expect("run length fits u32"),
                                data: d0,
                                stride: s,
                            });
                            for &(_, _, k) in seq.iter() {
                                used[k] = true;
                            }
                        }
                    }
                    seq.clear();
                };
                for (&i, &(d, k)) in line {
                    if seq.last().is_some_and(|&(j, _, _)| j + 1 != i) {
                        flush(&mut seq);
                    }
                    seq.push((i, d, k));
                }
                flush(&mut seq);
            }
        }
    }
    if runs.is_empty() {
        return None;
    }
    let rest = terms
        .iter()
        .zip(&used)
        .filter(|(_, &u)| !u)
        .map(|(&t, _)| t)
        .collect();
    Some((runs, rest))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One data slot of `len` entries.
    fn slot(len: u32) -> [Range<u32>; 1] {
        [Range { start: 0, end: len }]
    }

    /// `Σ_j c D[d0 + s j] x_{i0 + j}` for `j < len`, as terms.
    fn contraction(g: &mut Graph, c: f64, d0: u32, s: u32, i0: u32, len: u32) -> Vec<ExprId> {
        (0..len)
            .map(|j| {
                let d = g.var(Var::Data(d0 + s * j));
                let x = g.var(Var::Q(i0 + j));
                let c = g.constant(c);
                g.mul(vec![c, d, x])
            })
            .collect()
    }

    /// A row (stride 1) and a column (stride 10) of a 10 × 10 block against the same
    /// coordinates, with other terms, in one canonical sum: two runs, the rest kept.
    #[test]
    fn rows_and_columns_of_a_block_are_runs() {
        let mut g = Graph::new();
        let mut terms = contraction(&mut g, 1.0, 300, 1, 2, 10);
        terms.extend(contraction(&mut g, 1.0, 3, 10, 2, 10));
        let t = g.var(Var::Time);
        let short = contraction(&mut g, 2.0, 500, 1, 2, MIN_RUN as u32 - 1);
        terms.push(t);
        terms.extend(short.iter().copied());
        let sum = g.add(terms);
        let Node::Add(terms) = g.node(sum).clone() else {
            panic!("a sum")
        };
        let (mut runs, rest) = find(&g, &terms, &slot(1000)).expect("runs");
        runs.sort_by_key(|r| r.stride);
        let expect = |data, stride| Run {
            coef: 1.0,
            first: Var::Q(2),
            len: 10,
            data,
            stride,
        };
        assert_eq!(runs, vec![expect(300, 1), expect(3, 10)]);
        // The time and the run shorter than MIN_RUN stay terms.
        assert_eq!(rest.len(), 1 + short.len());
        assert!(rest.contains(&t));
    }

    /// A run crossing from one data slot into the next is not a contraction of a slot;
    /// coordinates that are not consecutive are not a run.
    #[test]
    fn runs_stay_in_one_slot_and_on_consecutive_coordinates() {
        let mut g = Graph::new();
        let terms = contraction(&mut g, -1.0, 95, 1, 0, 10);
        let sum = g.add(terms);
        let Node::Add(terms) = g.node(sum).clone() else {
            panic!("a sum")
        };
        assert!(find(&g, &terms, &[0..100, 100..200]).is_none());
        let (runs, rest) = find(&g, &terms, &slot(200)).expect("one slot");
        assert_eq!(runs.len(), 1);
        assert_eq!(runs[0].coef, -1.0);
        assert!(rest.is_empty());
        let gaps: Vec<ExprId> = (0..10)
            .map(|j| {
                let d = g.var(Var::Data(j));
                let x = g.var(Var::Qd(2 * j));
                g.mul(vec![d, x])
            })
            .collect();
        let sum = g.add(gaps);
        let Node::Add(terms) = g.node(sum).clone() else {
            panic!("a sum")
        };
        assert!(find(&g, &terms, &slot(200)).is_none());
    }

    /// The hub beam of `tests/benches/flex_modes.rs` with `n` modes, expanded.
    fn hub_beam(n: usize) -> String {
        let ps: Vec<String> = (1..=n).map(|i| format!("p{i}")).collect();
        let decl: String = ps
            .iter()
            .map(|p| format!("static {p}: Coordinate = Coordinate {{}};"))
            .collect();
        let src = format!(
            "mod hub {{
                static rod_fe: Data = Beam {{
                    elements: 32, length: 10.0, rho_a: 1.2, ea: 2.8e7, ei: 1.4e4, modes: {n}
                }};
                static theta: Coordinate = Coordinate {{}};
                {decl}
                static rod: Body = Deformable {{
                    origin: [0.0, 0.0], angle: theta, elastic: [{}], data: rod_fe
                }};
            }}",
            ps.join(", ")
        );
        let ts: proc_macro2::TokenStream = src.parse().expect("tokens");
        crate::expand(proc_macro2::TokenStream::new(), ts).to_string()
    }

    /// Doubling the modes of a beam-slot body from 16 to 32 multiplies its generated
    /// code by less than 3 (by 4.2 with every contraction unrolled: 0.77 → 3.2 MB, when
    /// 64 modes did not compile); 4 modes, below [`MIN_RUN`], have no loops.
    #[test]
    fn a_body_of_many_modes_emits_loops() {
        let (small, a, b) = (hub_beam(4), hub_beam(16), hub_beam(32));
        assert!(!small.contains("dot_strided"));
        assert!(a.contains("dot_strided") && b.contains("dot_strided"));
        let ratio = b.len() as f64 / a.len() as f64;
        assert!(ratio < 3.0, "16 → 32 modes: code × {ratio}");
    }
}
