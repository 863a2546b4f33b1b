//! One report row per checked function: cases, largest errors against AD and FD, the worst input.

use super::{CaseErrors, Tolerances};

/// Summary of one function's check.
#[derive(Clone, Debug)]
pub struct Report {
    /// the function's name
    pub name: String,
    /// input cases checked
    pub cases: usize,
    /// cases where the finite-difference comparison was skipped (too close to a kink)
    pub fd_skipped: usize,
    /// largest value error (relative normwise)
    pub max_value: f64,
    /// largest gradient error against AD
    pub max_gradient_ad: f64,
    /// largest Hessian error against AD
    pub max_hessian_ad: f64,
    /// largest gradient error against finite differences
    pub max_gradient_fd: f64,
    /// largest Hessian error against finite differences
    pub max_hessian_fd: f64,
    /// largest error-to-tolerance ratio over all checks and cases (≤ 1 passes)
    pub worst_ratio: f64,
    /// the input of the worst ratio
    pub worst_input: Vec<f64>,
    /// cases with a ratio > 1
    pub failures: usize,
}

impl Report {
    /// The summary of the errors of `cases` (input, errors) against the tolerances `tol`.
    pub fn from_cases(name: String, cases: &[(Vec<f64>, CaseErrors)], tol: &Tolerances) -> Report {
        let mut r = Report {
            name,
            cases: cases.len(),
            fd_skipped: 0,
            max_value: 0.0,
            max_gradient_ad: 0.0,
            max_hessian_ad: 0.0,
            max_gradient_fd: 0.0,
            max_hessian_fd: 0.0,
            worst_ratio: 0.0,
            worst_input: Vec::new(),
            failures: 0,
        };
        let upd = |m: &mut f64, e: f64| {
            *m = if e.is_nan() { f64::INFINITY } else { m.max(e) };
        };
        for (x, e) in cases {
            upd(&mut r.max_value, e.value);
            upd(&mut r.max_gradient_ad, e.gradient_ad);
            upd(&mut r.max_hessian_ad, e.hessian_ad);
            match (e.gradient_fd, e.hessian_fd) {
                (Some(g), Some(h)) => {
                    upd(&mut r.max_gradient_fd, g);
                    upd(&mut r.max_hessian_fd, h);
                }
                _ => r.fd_skipped += 1,
            }
            let ratio = e.worst_ratio(tol);
            if ratio > 1.0 {
                r.failures += 1;
            }
            if ratio > r.worst_ratio || r.worst_input.is_empty() {
                r.worst_ratio = ratio;
                r.worst_input = x.clone();
            }
        }
        r
    }

    /// Whether every case passed (and there was at least one).
    pub fn passed(&self) -> bool {
        self.failures == 0 && self.cases > 0
    }
}

/// The table printed by `check-derivatives`.
pub fn format_table(reports: &[Report]) -> String {
    let mut s = format!(
        "{:<34} {:>6} {:>9} {:>9} {:>9} {:>9} {:>9} {:>6} {:>7}  {:<6} worst input\n",
        "function",
        "cases",
        "value",
        "grad/AD",
        "hess/AD",
        "grad/FD",
        "hess/FD",
        "FDskip",
        "worst",
        "status"
    );
    for r in reports {
        // long inputs (a whole tile) are shortened to their first entries and their length
        const SHOWN: usize = 32;
        let mut input: Vec<String> = r
            .worst_input
            .iter()
            .take(SHOWN)
            .map(|v| format!("{v:.6e}"))
            .collect();
        if r.worst_input.len() > SHOWN {
            input.push(format!("… ({} values)", r.worst_input.len()));
        }
        s.push_str(&format!(
            "{:<34} {:>6} {:>9.2e} {:>9.2e} {:>9.2e} {:>9.2e} {:>9.2e} {:>6} {:>7.1e}  {:<6} [{}]\n",
            r.name,
            r.cases,
            r.max_value,
            r.max_gradient_ad,
            r.max_hessian_ad,
            r.max_gradient_fd,
            r.max_hessian_fd,
            r.fd_skipped,
            r.worst_ratio,
            if r.passed() { "ok" } else { "FAIL" },
            input.join(", ")
        ));
    }
    s
}
