//! Stepping order (Gauss-Seidel: connection order; Jacobi: file order), algebraic loops under
//! Gauss-Seidel, and instances whose last step is dropped.

use super::Checker;
use crate::fmu::VR;
use crate::model_description::{Causality, ModelDescription};
use crate::system::{Algorithm, PlanConnection};

impl Checker<'_> {
    /// The order in which instances step; under Gauss-Seidel an algebraic loop is a warning.
    pub(super) fn order(&mut self, connections: &[PlanConnection]) -> Vec<usize> {
        let n = self.sys.instances.len();
        match self.sys.algorithm {
            Algorithm::Jacobi => (0..n).collect(),
            Algorithm::GaussSeidel => {
                let mut order = Vec::new();
                let mut seen = vec![false; n];
                for c in connections {
                    for i in [c.from_instance, c.to_instance] {
                        if !seen[i] {
                            seen[i] = true;
                            order.push(i);
                        }
                    }
                }
                order.extend((0..n).filter(|&i| !seen[i]));
                if let Some(cycle) = find_algebraic_loop(connections, self.mds) {
                    self.warnings.push(format!(
                        "{}: algebraic loop under Gauss-Seidel: {cycle}; the loop is not iterated, the first instance in stepping order uses the previous step's value",
                        self.loc(None)));
                }
                order
            }
        }
    }

    /// An instance with step multiple m > 1 that cannot take a shorter last step loses it when
    /// the run is not a whole number of its steps: a warning.
    pub(super) fn step_multiples(&mut self, n_steps: u64) {
        let sys = self.sys;
        for (i, inst) in sys.instances.iter().enumerate() {
            let m = inst.step_multiple;
            if m > 1 && n_steps % m as u64 != 0 {
                let cs = self.mds[i].co_simulation.as_ref();
                if !cs
                    .map(|c| c.can_handle_variable_communication_step_size)
                    .unwrap_or(false)
                {
                    self.warnings.push(format!("{}: instance '{}' steps every {m} base steps but the run has {n_steps}; its last step is dropped (it cannot handle variable communication steps)", self.loc(inst.line), inst.name));
                }
            }
        }
    }
}

/// Finds a cycle of direct feed-through: connection a.y -> b.u, and within b an output that
/// depends on u (ModelStructure), and so on back to a. Returns it as text.
fn find_algebraic_loop(conns: &[PlanConnection], mds: &[&ModelDescription]) -> Option<String> {
    // Graph over connections: edge c1 -> c2 if c2 leaves the instance c1 enters, and c2's source
    // output depends on c1's target input.
    let vr_index = |i: usize, vr: VR, input: bool| -> Option<usize> {
        mds[i].model_variables.variables.iter().position(|v| {
            v.value_reference == vr
                && if input {
                    v.causality == Causality::Input
                } else {
                    v.causality != Causality::Input
                }
        })
    };
    let n = conns.len();
    let mut adj = vec![Vec::new(); n];
    for (a, ca) in conns.iter().enumerate() {
        for (b, cb) in conns.iter().enumerate() {
            if cb.from_instance == ca.to_instance {
                let inp = vr_index(ca.to_instance, ca.to_vr, true);
                let out = vr_index(cb.from_instance, cb.from_vr, false);
                if let (Some(inp), Some(out)) = (inp, out) {
                    if mds[ca.to_instance].output_depends_on(out, inp) {
                        adj[a].push(b);
                    }
                }
            }
        }
    }
    // DFS cycle detection.
    let mut state = vec![0u8; n];
    let mut stack = Vec::new();
    fn dfs(
        u: usize,
        adj: &[Vec<usize>],
        state: &mut [u8],
        stack: &mut Vec<usize>,
    ) -> Option<Vec<usize>> {
        state[u] = 1;
        stack.push(u);
        for &v in &adj[u] {
            if state[v] == 1 {
                let pos = stack.iter().position(|&x| x == v).unwrap();
                return Some(stack[pos..].to_vec());
            }
            if state[v] == 0 {
                if let Some(c) = dfs(v, adj, state, stack) {
                    return Some(c);
                }
            }
        }
        stack.pop();
        state[u] = 2;
        None
    }
    for s in 0..n {
        if state[s] == 0 {
            if let Some(c) = dfs(s, &adj, &mut state, &mut stack) {
                return Some(
                    c.iter()
                        .map(|&i| conns[i].name.clone())
                        .collect::<Vec<_>>()
                        .join(", "),
                );
            }
        }
    }
    None
}
