//! A conic program with a fixed sparsity pattern, solved (and re-solved after
//! in-place data updates) with Clarabel.
//!
//! Problem builders emit the constraint matrix as a sequence of `(row, col,
//! value)` slots in the same order every time; the first emission fixes the
//! CSC pattern and the slot-to-nonzero map, later ones only refill values
//! (never dropping zeros), so the solver's symbolic factorisation is reused.

use crate::error::{Error, Result};
use clarabel::algebra::CscMatrix;
use clarabel::solver::{
    DefaultSettings, DefaultSettingsBuilder, DefaultSolver, IPSolver, SolverStatus, SupportedConeT,
};

/// Cones in the order their rows appear.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Cone {
    Zero(usize),
    Nonneg(usize),
    Soc(usize),
}

/// Outcome of one solve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum SolveStatus {
    Solved,
    /// Solved to reduced accuracy.
    AlmostSolved,
    Infeasible,
    Unbounded,
    IterationLimit,
    NumericalError,
}

impl SolveStatus {
    fn from_clarabel(s: SolverStatus) -> Self {
        match s {
            SolverStatus::Solved => SolveStatus::Solved,
            SolverStatus::AlmostSolved => SolveStatus::AlmostSolved,
            SolverStatus::PrimalInfeasible | SolverStatus::AlmostPrimalInfeasible => {
                SolveStatus::Infeasible
            }
            SolverStatus::DualInfeasible | SolverStatus::AlmostDualInfeasible => {
                SolveStatus::Unbounded
            }
            SolverStatus::MaxIterations | SolverStatus::MaxTime => SolveStatus::IterationLimit,
            _ => SolveStatus::NumericalError,
        }
    }

    pub fn ok(self) -> bool {
        matches!(self, SolveStatus::Solved | SolveStatus::AlmostSolved)
    }
}

/// Linear objective, constraint rows `A x + s = b`, `s` in the cones.
#[derive(Debug, Clone, Default)]
pub struct ConicData {
    pub n: usize,
    pub q: Vec<f64>,
    /// Optional diagonal quadratic term `1/2 x' diag(p) x` (fixed pattern: all `n` entries).
    pub p_diag: Option<Vec<f64>>,
    /// More quadratic terms: upper-triangle `(row, col, value)` slots of `P`
    /// (`row <= col`), added to the diagonal; fixed pattern like `A`.
    pub p_upper: Vec<(usize, usize, f64)>,
    pub rows: Vec<usize>,
    pub cols: Vec<usize>,
    pub vals: Vec<f64>,
    pub b: Vec<f64>,
    pub cones: Vec<Cone>,
}

impl ConicData {
    pub fn new(n: usize) -> Self {
        Self {
            n,
            q: vec![0.0; n],
            ..Default::default()
        }
    }

    /// Appends a row; returns its index.
    pub fn row(&mut self, entries: &[(usize, f64)], b: f64) -> usize {
        let r = self.b.len();
        for &(c, v) in entries {
            self.rows.push(r);
            self.cols.push(c);
            self.vals.push(v);
        }
        self.b.push(b);
        r
    }

    pub fn cone(&mut self, c: Cone) {
        match (self.cones.last_mut(), c) {
            (Some(Cone::Zero(k)), Cone::Zero(m)) => *k += m,
            (Some(Cone::Nonneg(k)), Cone::Nonneg(m)) => *k += m,
            _ => self.cones.push(c),
        }
    }

    pub fn m(&self) -> usize {
        self.b.len()
    }
}

/// A Clarabel solver bound to one sparsity pattern.
pub struct ConicSolver {
    solver: DefaultSolver<f64>,
    slot: Vec<usize>,
    nnz: usize,
    n: usize,
    m: usize,
    cones: Vec<Cone>,
    has_p: bool,
    settings: ConicSettings,
    /// Slot map of `P`'s entries (diagonal first, then `p_upper`).
    p_slot: Vec<usize>,
    p_nnz: usize,
    kkt: Option<Kkt>,
}

/// The KKT matrix `[P A'; A -H]` of a solved program (upper triangle), with
/// its fixed pattern and factorisation reused across solves
/// ([`ConicSolver::kkt_at_solution`]).
pub struct Kkt {
    colptr: Vec<usize>,
    rowval: Vec<usize>,
    /// Nonzero slot of each entry of [`kkt_entries`].
    pos: Vec<usize>,
    /// The values without the static regularisation.
    exact: Vec<f64>,
    /// Diagonal slot of each column.
    diag: Vec<usize>,
    /// Every slot (QDLDL's value update takes a slot list).
    slots: Vec<usize>,
    n: usize,
    factor: clarabel::qdldl::QDLDLFactorisation<f64>,
}

/// Static regularisation of the KKT's diagonal (`+` primal, `-` dual),
/// removed again by iterative refinement.
const KKT_REG: f64 = 1e-9;

/// The entries `(row, col, value)` (`row <= col`) of `[P A'; A -H]` at the
/// last solution, in a fixed order: `P`, the diagonal, `A'`, then `-H`
/// cone by cone (`H = s / z` for a nonnegative row, zero for an equality,
/// the Nesterov-Todd `W'W` for a second-order cone).
fn kkt_entries(d: &ConicData, s: &[f64], z: &[f64]) -> Option<Vec<(usize, usize, f64)>> {
    let n = d.n;
    let mut e = Vec::with_capacity(d.p_upper.len() + d.vals.len() + 2 * n + 2 * d.m());
    if let Some(pd) = &d.p_diag {
        e.extend(pd.iter().enumerate().map(|(j, &v)| (j, j, v)));
    }
    e.extend(d.p_upper.iter().copied());
    e.extend((0..n).map(|j| (j, j, 0.0)));
    e.extend((0..d.rows.len()).map(|k| (d.cols[k], n + d.rows[k], d.vals[k])));
    let mut r0 = 0;
    for c in &d.cones {
        match *c {
            Cone::Zero(k) => e.extend((r0..r0 + k).map(|r| (n + r, n + r, 0.0))),
            Cone::Nonneg(k) => e.extend((r0..r0 + k).map(|r| (n + r, n + r, -s[r] / z[r]))),
            Cone::Soc(k) => {
                let h = soc_scaling(&s[r0..r0 + k], &z[r0..r0 + k])?;
                for b in 0..k {
                    for a in 0..=b {
                        e.push((n + r0 + a, n + r0 + b, -h[a * k + b]));
                    }
                }
            }
        }
        r0 += match *c {
            Cone::Zero(k) | Cone::Nonneg(k) | Cone::Soc(k) => k,
        };
    }
    Some(e)
}

impl Kkt {
    /// The pattern of `entries` and its symbolic factorisation (ordering);
    /// [`Kkt::refactor`] fills the values.
    fn new(dim: usize, n: usize, entries: &[(usize, usize, f64)]) -> Option<Self> {
        use clarabel::qdldl::{QDLDLFactorisation, QDLDLSettingsBuilder};
        let rows: Vec<usize> = entries.iter().map(|e| e.0).collect();
        let cols: Vec<usize> = entries.iter().map(|e| e.1).collect();
        let (colptr, rowval, pos) = csc(dim, dim, &rows, &cols);
        let nnz = rowval.len();
        let diag: Vec<usize> = (0..dim)
            .map(|j| (colptr[j]..colptr[j + 1]).find(|&k| rowval[k] == j))
            .collect::<Option<_>>()?;
        let a = CscMatrix::new(dim, dim, colptr.clone(), rowval.clone(), vec![0.0; nnz]);
        let signs: Vec<i8> = (0..dim).map(|j| if j < n { 1 } else { -1 }).collect();
        let opts = QDLDLSettingsBuilder::default()
            .Dsigns(signs)
            .logical(true)
            .build()
            .ok()?;
        let factor = QDLDLFactorisation::new(&a, Some(opts)).ok()?;
        Some(Self {
            exact: vec![0.0; nnz],
            slots: (0..nnz).collect(),
            colptr,
            rowval,
            pos,
            diag,
            n,
            factor,
        })
    }

    fn refactor(&mut self, entries: &[(usize, usize, f64)]) -> Option<()> {
        self.exact.fill(0.0);
        for (&p, e) in self.pos.iter().zip(entries) {
            self.exact[p] += e.2;
        }
        let mut values = self.exact.clone();
        for (j, &k) in self.diag.iter().enumerate() {
            values[k] += if j < self.n { KKT_REG } else { -KKT_REG };
        }
        self.factor.update_values(&self.slots, &values);
        self.factor.refactor().ok()
    }

    /// The change `dx` of the solution for a change `db` of `b`: `K [dx;
    /// dy] = [0; db]`.
    pub fn primal_change(&mut self, db: &[f64]) -> Vec<f64> {
        let mut rhs = vec![0.0; self.n];
        rhs.extend_from_slice(db);
        let mut x = self.solve(&rhs);
        x.truncate(self.n);
        x
    }

    /// `K x = rhs`, refined against the unregularised `K`.
    fn solve(&mut self, rhs: &[f64]) -> Vec<f64> {
        let mut x = rhs.to_vec();
        self.factor.solve(&mut x);
        for _ in 0..3 {
            let mut r = rhs.to_vec();
            for j in 0..rhs.len() {
                for k in self.colptr[j]..self.colptr[j + 1] {
                    let (i, v) = (self.rowval[k], self.exact[k]);
                    r[i] -= v * x[j];
                    if i != j {
                        r[j] -= v * x[i];
                    }
                }
            }
            self.factor.solve(&mut r);
            x.iter_mut().zip(&r).for_each(|(a, b)| *a += b);
        }
        x
    }
}

/// How exactly each conic program is solved; settings live apart from the
/// problem data, as in Clarabel.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize)]
pub struct ConicSettings {
    /// Iterative refinement of each KKT solve, to [`REFINE_TOL`] (default
    /// on): the phased design's certified optima and the envelope's least
    /// heights keep 7 digits. Off, an interior-point iteration is one
    /// factorisation and two triangular solves.
    pub refine: bool,
    /// Clarabel's duality-gap tolerance, absolute and relative (default
    /// 1e-8, Clarabel's).
    pub gap_tolerance: f64,
}

impl Default for ConicSettings {
    fn default() -> Self {
        Self {
            refine: true,
            gap_tolerance: 1e-8,
        }
    }
}

impl ConicSettings {
    /// The SCP's subproblems and corrections: models of the problem, whose
    /// predicted decrease needs ~1e-6 of the merit, so they are solved
    /// without refinement and to a looser gap than Clarabel's default: fewer
    /// iterations and instructions, to about the same peaks (measured:
    /// docs/benchmarks.md, "Design settings: the measurements behind them").
    pub const MODEL: Self = Self {
        refine: false,
        gap_tolerance: 1e-7,
    };

    /// The subproblems of a coarse mesh of the continuation, whose design
    /// only starts the finer one (to a criticality of 1e-3), so they are
    /// solved to a looser gap, 1e-5 (looser still saves little more); the
    /// finer meshes keep [`ConicSettings::MODEL`], so the designs keep their
    /// accuracy (measured: docs/benchmarks.md, "Design settings: the
    /// measurements behind them").
    pub const COARSE: Self = Self {
        refine: false,
        gap_tolerance: 1e-5,
    };

    /// A search that only ranks candidates (the phased bend search), whose
    /// winner is solved again with the defaults: no refinement.
    pub const SEARCH: Self = Self {
        refine: false,
        gap_tolerance: 1e-8,
    };
}

/// Iterative-refinement stopping tolerance (relative and absolute) of the
/// KKT solves when refining (Clarabel's defaults: 1e-13 relative, 1e-12
/// absolute): the designs need no more, and the tighter defaults cost work
/// for the same iterations and peaks (measured: docs/benchmarks.md,
/// "Design settings: the measurements behind them").
pub const REFINE_TOL: f64 = 1e-10;

fn clarabel_settings(s: ConicSettings) -> DefaultSettings<f64> {
    DefaultSettingsBuilder::default()
        .verbose(false)
        .presolve_enable(false)
        .input_sparse_dropzeros(false)
        .max_iter(200)
        .iterative_refinement_enable(s.refine)
        .iterative_refinement_reltol(REFINE_TOL)
        .iterative_refinement_abstol(REFINE_TOL)
        .tol_gap_abs(s.gap_tolerance)
        .tol_gap_rel(s.gap_tolerance)
        .build()
        .expect("valid Clarabel settings")
}

/// Compressed-column pattern of the triplets `(rows[k], cols[k])`:
/// `(colptr, rowval, slot)`, rows ascending within each column, duplicates
/// merged, `slot[k]` the position of triplet `k`. The slots are bucketed by
/// column (a counting sort) and each column's few entries sorted by row,
/// which is cheaper than one comparison sort of all the triplets (measured:
/// docs/benchmarks.md, "Design settings: the measurements behind them").
fn csc(m: usize, n: usize, rows: &[usize], cols: &[usize]) -> (Vec<usize>, Vec<usize>, Vec<usize>) {
    let mut start = vec![0usize; n + 1];
    for &c in cols {
        start[c + 1] += 1;
    }
    for c in 0..n {
        start[c + 1] += start[c];
    }
    let mut order = vec![0usize; rows.len()];
    let mut next = start.clone();
    for (k, &c) in cols.iter().enumerate() {
        order[next[c]] = k;
        next[c] += 1;
    }
    let mut colptr = vec![0usize; n + 1];
    let mut rowval = Vec::with_capacity(rows.len());
    let mut slot = vec![0usize; rows.len()];
    for c in 0..n {
        let column = &mut order[start[c]..start[c + 1]];
        column.sort_unstable_by_key(|&k| rows[k]);
        let mut last = None;
        for &k in column.iter() {
            if last != Some(rows[k]) {
                rowval.push(rows[k]);
                last = Some(rows[k]);
            }
            slot[k] = rowval.len() - 1;
        }
        colptr[c + 1] = rowval.len();
    }
    debug_assert!(rows.iter().all(|&r| r < m));
    (colptr, rowval, slot)
}

/// `P`'s slots: the diagonal (if any) then the upper-triangle triplets.
fn p_entries(data: &ConicData) -> (Vec<usize>, Vec<usize>, Vec<f64>) {
    let (mut r, mut c, mut v) = (Vec::new(), Vec::new(), Vec::new());
    if let Some(d) = &data.p_diag {
        r.extend(0..data.n);
        c.extend(0..data.n);
        v.extend(d);
    }
    for &(i, j, x) in &data.p_upper {
        debug_assert!(i <= j);
        r.push(i);
        c.push(j);
        v.push(x);
    }
    (r, c, v)
}

fn fill(slot: &[usize], nnz: usize, vals: &[f64]) -> Vec<f64> {
    let mut nz = vec![0.0; nnz];
    for (i, &s) in slot.iter().enumerate() {
        nz[s] += vals[i];
    }
    nz
}

impl ConicSolver {
    pub fn new(data: &ConicData) -> Result<Self> {
        Self::with_settings(data, ConicSettings::default())
    }

    /// [`ConicSolver::new`] with explicit settings.
    pub fn with_settings(data: &ConicData, settings: ConicSettings) -> Result<Self> {
        let (m, n) = (data.m(), data.n);
        let (colptr, rowval, slot) = csc(m, n, &data.rows, &data.cols);
        let nnz = rowval.len();
        let mut nz = vec![0.0; nnz];
        for (i, &s) in slot.iter().enumerate() {
            nz[s] += data.vals[i];
        }
        let a = CscMatrix::new(m, n, colptr, rowval, nz);
        let cones: Vec<SupportedConeT<f64>> = data
            .cones
            .iter()
            .map(|c| match *c {
                Cone::Zero(k) => SupportedConeT::ZeroConeT(k),
                Cone::Nonneg(k) => SupportedConeT::NonnegativeConeT(k),
                Cone::Soc(k) => SupportedConeT::SecondOrderConeT(k),
            })
            .collect();
        let (pr, pc, pv) = p_entries(data);
        let (pcolptr, prowval, p_slot) = csc(n, n, &pr, &pc);
        let p_nnz = prowval.len();
        let p = CscMatrix::new(n, n, pcolptr, prowval, fill(&p_slot, p_nnz, &pv));
        let solver = DefaultSolver::new(
            &p,
            &data.q,
            &a,
            &data.b,
            &cones,
            clarabel_settings(settings),
        )
        .map_err(|e| Error::Solver {
            what: "setting up the conic program".into(),
            status: "setup error".into(),
            hint: format!("{e}; this is a bug in the problem builder, please report it"),
        })?;
        Ok(Self {
            solver,
            slot,
            nnz,
            n,
            m,
            cones: data.cones.clone(),
            has_p: data.p_diag.is_some(),
            settings,
            p_slot,
            p_nnz,
            kkt: None,
        })
    }

    /// Whether `data` has this solver's pattern (same slots, sizes, cones).
    pub fn fits(&self, data: &ConicData) -> bool {
        data.n == self.n
            && data.m() == self.m
            && data.vals.len() == self.slot.len()
            && data.cones == self.cones
            && data.p_diag.is_some() == self.has_p
            && data.p_upper.len() + if self.has_p { self.n } else { 0 } == self.p_slot.len()
    }

    /// Replaces all data values in place (same pattern).
    pub fn update(&mut self, data: &ConicData) -> Result<()> {
        assert!(self.fits(data), "conic data pattern changed");
        let mut nz = vec![0.0; self.nnz];
        for (i, &s) in self.slot.iter().enumerate() {
            nz[s] += data.vals[i];
        }
        let err = |e: clarabel::solver::DataUpdateError| Error::Solver {
            what: "updating the conic program".into(),
            status: "update error".into(),
            hint: e.to_string(),
        };
        self.solver.update_A(&nz).map_err(err)?;
        self.solver.update_b(&data.b).map_err(err)?;
        self.solver.update_q(&data.q).map_err(err)?;
        if !self.p_slot.is_empty() {
            let (_, _, pv) = p_entries(data);
            self.solver
                .update_P(&fill(&self.p_slot, self.p_nnz, &pv))
                .map_err(err)?;
        }
        Ok(())
    }

    /// Solves; returns the status, the primal solution and the objective.
    pub fn solve(&mut self) -> (SolveStatus, Vec<f64>, f64) {
        self.solver.solve();
        let s = &self.solver.solution;
        (SolveStatus::from_clarabel(s.status), s.x.clone(), s.obj_val)
    }

    /// Interior-point iterations of the last solve.
    pub fn iterations(&self) -> u32 {
        self.solver.solution.iterations
    }

    /// The KKT system of the last solution, `[P A'; A -H]` with the
    /// interior point's final Nesterov-Todd scaling `H` (`H z = s`, per
    /// cone), factored: [`Kkt::primal_change`] gives the first-order change
    /// of the solution when `b` changes, with the solution's own active set
    /// (a row that binds, `s ~ 0`, is held; one with room, `z ~ 0`, lets its
    /// slack take the change). `data` is the last solve's. `None` if the
    /// factorisation fails or a second-order cone's `s` or `z` is not
    /// strictly inside it.
    pub fn kkt_at_solution(&mut self, data: &ConicData) -> Option<&mut Kkt> {
        debug_assert!(self.fits(data), "the last solve's data");
        let sol = &self.solver.solution;
        let entries = kkt_entries(data, &sol.s, &sol.z)?;
        if self
            .kkt
            .as_ref()
            .is_none_or(|k| k.pos.len() != entries.len())
        {
            self.kkt = Some(Kkt::new(self.n + self.m, self.n, &entries)?);
        }
        let kkt = self.kkt.as_mut()?;
        kkt.refactor(&entries)?;
        Some(kkt)
    }

    /// The dual solution `z` of the last solve (one per row; the
    /// Lagrangian is `q'x + z'(A x - b)`).
    pub fn duals(&self) -> &[f64] {
        &self.solver.solution.z
    }
}

/// The Nesterov-Todd scaling `W'W` of a second-order cone at interior
/// `(s, z)` (dense, row-major): `eta^2 (2 w w' - J)`, `J = diag(1, -I)`,
/// with `W'W z = s` (Clarabel's own formula).
fn soc_scaling(s: &[f64], z: &[f64]) -> Option<Vec<f64>> {
    let k = s.len();
    let res = |v: &[f64]| {
        let r = v[0] * v[0] - v[1..].iter().map(|x| x * x).sum::<f64>();
        (r > 0.0).then(|| r.sqrt())
    };
    let (ss, zs) = (res(s)?, res(z)?);
    let eta2 = ss / zs;
    let mut w: Vec<f64> = s.iter().map(|v| v / ss).collect();
    w[0] += z[0] / zs;
    for i in 1..k {
        w[i] -= z[i] / zs;
    }
    let ws = res(&w)?;
    w.iter_mut().for_each(|v| *v /= ws);
    let mut h = vec![0.0; k * k];
    for a in 0..k {
        for b in 0..k {
            let j = if a != b {
                0.0
            } else if a == 0 {
                1.0
            } else {
                -1.0
            };
            h[a * k + b] = eta2 * (2.0 * w[a] * w[b] - j);
        }
    }
    Some(h)
}

/// Builds a solver for `data`, or refills `slot`'s solver if the pattern fits.
pub fn solve_reusing(
    slot: &mut Option<ConicSolver>,
    data: &ConicData,
) -> Result<(SolveStatus, Vec<f64>, f64)> {
    solve_reusing_with(slot, data, ConicSettings::default())
}

/// [`solve_reusing`] with explicit settings (a solver built with other
/// settings is rebuilt).
pub fn solve_reusing_with(
    slot: &mut Option<ConicSolver>,
    data: &ConicData,
    settings: ConicSettings,
) -> Result<(SolveStatus, Vec<f64>, f64)> {
    match slot {
        Some(s) if s.settings == settings && s.fits(data) => s.update(data)?,
        _ => *slot = Some(ConicSolver::with_settings(data, settings)?),
    }
    Ok(slot.as_mut().unwrap().solve())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_compressed_pattern_sorts_merges_and_maps_every_triplet() {
        // a pseudo-random pattern with many duplicates and empty columns
        let (m, n) = (37, 23);
        let mut x: u64 = 0x9e37_79b9_7f4a_7c15;
        let mut draw = |k: usize| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            (x % k as u64) as usize
        };
        let (rows, cols): (Vec<usize>, Vec<usize>) =
            (0..400).map(|_| (draw(m), 2 * draw(n / 2))).unzip();
        let (colptr, rowval, slot) = csc(m, n, &rows, &cols);
        assert_eq!(colptr.len(), n + 1);
        assert_eq!(colptr[n], rowval.len());
        let mut distinct: Vec<(usize, usize)> =
            cols.iter().copied().zip(rows.iter().copied()).collect();
        distinct.sort();
        distinct.dedup();
        assert_eq!(rowval.len(), distinct.len());
        for c in 0..n {
            let column = &rowval[colptr[c]..colptr[c + 1]];
            assert!(
                column.windows(2).all(|w| w[0] < w[1]),
                "column {c}: {column:?}"
            );
            if c % 2 == 1 {
                assert!(column.is_empty());
            }
        }
        for k in 0..rows.len() {
            let s = slot[k];
            assert_eq!(rowval[s], rows[k]);
            assert!(colptr[cols[k]] <= s && s < colptr[cols[k] + 1]);
        }
    }

    #[test]
    fn small_socp_and_update_in_place() {
        // minimise t s.t. ||(x - 1, y - 2)|| <= t, x + y = c: optimum distance from (1,2) to the line
        let build = |c: f64| {
            let mut d = ConicData::new(3);
            d.q[2] = 1.0;
            d.row(&[(0, 1.0), (1, 1.0)], c);
            d.cone(Cone::Zero(1));
            d.row(&[(2, -1.0)], 0.0);
            d.row(&[(0, -1.0)], -1.0);
            d.row(&[(1, -1.0)], -2.0);
            d.cone(Cone::Soc(3));
            d
        };
        let mut slot = None;
        for c in [0.0, 3.0, 7.0] {
            let (st, x, _) = solve_reusing(&mut slot, &build(c)).unwrap();
            assert_eq!(st, SolveStatus::Solved);
            let want = (c - 3.0f64).abs() / 2f64.sqrt();
            assert!((x[2] - want).abs() < 1e-7, "{c}: {} vs {want}", x[2]);
        }
        // infeasible: x + y = 1 and x + y = 2
        let mut d = ConicData::new(2);
        d.row(&[(0, 1.0), (1, 1.0)], 1.0);
        d.row(&[(0, 1.0), (1, 1.0)], 2.0);
        d.cone(Cone::Zero(2));
        let (st, _, _) = ConicSolver::new(&d).unwrap().solve();
        assert_eq!(st, SolveStatus::Infeasible);
    }

    #[test]
    fn soc_scaling_maps_z_to_s() {
        let (s, z) = ([2.0, 0.5, -1.0], [1.5, -0.3, 0.8]);
        let h = soc_scaling(&s, &z).unwrap();
        for a in 0..3 {
            let hz: f64 = (0..3).map(|b| h[a * 3 + b] * z[b]).sum();
            assert!((hz - s[a]).abs() < 1e-12, "{a}: {hz} vs {}", s[a]);
        }
        // the Nesterov-Todd scaling of the cone: H J H = eta^4 J with
        // eta^4 = (s'Js) / (z'Jz), and H positive definite
        let jn = |v: &[f64; 3]| v[0] * v[0] - v[1] * v[1] - v[2] * v[2];
        let eta4 = jn(&s) / jn(&z);
        let j = [1.0, -1.0, -1.0];
        for a in 0..3 {
            for b in 0..3 {
                let hjh: f64 = (0..3).map(|k| h[a * 3 + k] * j[k] * h[k * 3 + b]).sum();
                let want = if a == b { eta4 * j[a] } else { 0.0 };
                assert!((hjh - want).abs() < 1e-12, "({a}, {b}): {hjh} vs {want}");
            }
        }
        let m = nalgebra::Matrix3::from_row_slice(&h);
        assert!(m.symmetric_eigenvalues().iter().all(|&e| e > 0.0));
    }

    #[test]
    fn the_kkt_at_a_solution_gives_the_solutions_change_with_b() {
        // minimise t s.t. ||(x - 1, y - 2)|| <= t, x + y = c, x <= u: the
        // point of the line nearest (1, 2) is (3, 4) for c = 7; with u = 2.5
        // the bound binds and the solution is (u, c - u)
        let build = |c: f64, u: f64| {
            let mut d = ConicData::new(3);
            d.q[2] = 1.0;
            d.row(&[(0, 1.0), (1, 1.0)], c);
            d.cone(Cone::Zero(1));
            d.row(&[(0, 1.0)], u);
            d.cone(Cone::Nonneg(1));
            d.row(&[(2, -1.0)], 0.0);
            d.row(&[(0, -1.0)], -1.0);
            d.row(&[(1, -1.0)], -2.0);
            d.cone(Cone::Soc(3));
            d
        };
        let data = build(7.0, 2.5);
        let mut solver = ConicSolver::new(&data).unwrap();
        let (st, x, _) = solver.solve();
        assert_eq!(st, SolveStatus::Solved);
        assert!(
            (x[0] - 2.5).abs() < 1e-6 && (x[1] - 4.5).abs() < 1e-6,
            "{x:?}"
        );
        let kkt = solver.kkt_at_solution(&data).unwrap();
        // d/dc: x held by the bound, y = c - u, t = |(x - 1, y - 2)|
        let dt_dy = 2.5 / (1.5f64.powi(2) + 2.5f64.powi(2)).sqrt();
        let dx = kkt.primal_change(&[1.0, 0.0, 0.0, 0.0, 0.0]);
        for (got, want) in dx.iter().zip([0.0, 1.0, dt_dy]) {
            assert!((got - want).abs() < 1e-4, "d/dc: {dx:?}");
        }
        // d/du: x = u, y = c - u
        let dx = kkt.primal_change(&[0.0, 1.0, 0.0, 0.0, 0.0]);
        let dt_du = (1.5 - 2.5) / (1.5f64.powi(2) + 2.5f64.powi(2)).sqrt();
        for (got, want) in dx.iter().zip([1.0, -1.0, dt_du]) {
            assert!((got - want).abs() < 1e-4, "d/du: {dx:?}");
        }
        // a bound with room (u = 5) lets its slack take the change
        let data = build(7.0, 5.0);
        let mut solver = ConicSolver::new(&data).unwrap();
        solver.solve();
        let dx = solver
            .kkt_at_solution(&data)
            .unwrap()
            .primal_change(&[0.0, 1.0, 0.0, 0.0, 0.0]);
        assert!(dx.iter().all(|v| v.abs() < 1e-4), "{dx:?}");
    }
}
