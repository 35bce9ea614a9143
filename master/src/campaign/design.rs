//! The runs of a campaign: design points × replications × arms.
//!
//! **Design points.** Grid factors are crossed in file order, the first factor varying
//! slowest; factors with the same `zip` label vary together (equal lengths) as one dimension,
//! placed where the first of them appears. The random factors (uniform, normal) form one more
//! dimension of `sampling.samples` points, placed where the first random factor appears.
//!
//! **Random points.** Every number drawn is a function of the campaign seed, the factor's name
//! and the sample index only, so adding factors or samples never changes an existing point:
//!
//! - `u(label, i) = (h + 0.5) / 2^53` with `h` the first 53 bits of
//!   SHA-256(`"shipsim-campaign-v1/" label "/" seed "/" i`) (big-endian), a number in (0, 1);
//! - Monte Carlo: `u(factor, i)`;
//! - Latin hypercube (McKay, Beckman & Conover 1979): sample i of a factor lies in stratum
//!   `π(i)` of n equal strata, `(π(i) + u(factor, i)) / n`, where π is the permutation of
//!   0..n ordered by `u(factor + "#lhs", k)`. Stratification depends on n, so changing
//!   `samples` changes the points (seeds do not change);
//! - uniform on [a, b]: `a + u (b - a)`; normal: `mean + std Φ⁻¹(u)`.
//!
//! **Seeds.** Replication r (0-based) gives seed parameter `p` (e.g. `waves.seed`) the value
//! `S(p, r) = first 8 bytes of SHA-256("shipsim-campaign-v1/seed/" campaign_seed "/" p "/" r),
//! big-endian, mod 2^31 - 1`: a value in 0 ..= 2147483646 that fits an FMI Integer. It depends
//! on nothing else, so every design point and every arm of replication r runs on the same
//! seeds (common random numbers), and adding factors, points or replications never changes an
//! existing run's seeds.
//!
//! **Run order.** `index = (point · R + r) · A + arm`. A run's key (for resume) is the
//! SHA-256 of everything that determines it: the base inputs' hash (system and FMU files),
//! the stop time, the warm-up time and every value set, sorted.
//!
//! **Runs on demand.** A [`Design`] holds the factors' levels, not the runs: run i is made from
//! i when it is needed (its point is a mixed-radix number over the dimensions' levels), so a
//! campaign of [`MAX_RUNS`] runs is shown and counted in the memory of its levels. Two runs
//! that set the same values are found without making the runs ([`distinct`]).

use super::spec::{CampaignSpec, Factor, Levels, SamplingMethod, MAX_RUNS};
use crate::error::{Error, Result};
use crate::system::Value;
use sha2::{Digest, Sha256};

mod distinct;

/// One run of the campaign.
#[derive(Debug, Clone, PartialEq)]
pub struct Run {
    pub index: usize,
    pub point: usize,
    pub replication: u32,
    /// Index into the campaign's arms (0 without arms).
    pub arm: usize,
    /// The factor columns' values (before the factor's scale), in factor order.
    pub factors: Vec<f64>,
    /// The derived seeds, in the order of `replications.seeds`.
    pub seeds: Vec<i64>,
    /// Every value the run sets: common sets, factors (scaled), seeds, arm sets — later ones
    /// win, so an arm can override a factor.
    pub sets: Vec<(String, Value)>,
    /// Hex SHA-256 of the run's full parameter set (see the module documentation).
    pub key: String,
}

/// The first 8 bytes of SHA-256(text), big-endian.
fn hash64(text: &str) -> u64 {
    let d = Sha256::digest(text.as_bytes());
    u64::from_be_bytes(d[..8].try_into().expect("8 bytes"))
}

/// A number in (0, 1) from (label, index) (the module documentation's `u`).
fn uniform01(seed: u64, label: &str, i: usize) -> f64 {
    let h = hash64(&format!("shipsim-campaign-v1/{label}/{seed}/{i}")) >> 11;
    (h as f64 + 0.5) / (1u64 << 53) as f64
}

/// The seed of parameter `param` in replication `r` (the module documentation's `S`).
pub fn derived_seed(campaign_seed: u64, param: &str, r: u32) -> i64 {
    (hash64(&format!(
        "shipsim-campaign-v1/seed/{campaign_seed}/{param}/{r}"
    )) % (i32::MAX as u64)) as i64
}

/// The `samples` values in (0, 1) of one random factor.
fn unit_samples(spec: &CampaignSpec, factor: &str) -> Vec<f64> {
    let n = spec.sampling.samples;
    let seed = spec.seed;
    match spec.sampling.method {
        SamplingMethod::MonteCarlo => (0..n).map(|i| uniform01(seed, factor, i)).collect(),
        SamplingMethod::LatinHypercube => {
            let lhs = format!("{factor}#lhs");
            let mut order: Vec<(f64, usize)> =
                (0..n).map(|k| (uniform01(seed, &lhs, k), k)).collect();
            order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            let mut stratum = vec![0usize; n];
            for (rank, (_, k)) in order.into_iter().enumerate() {
                stratum[k] = rank;
            }
            (0..n)
                .map(|i| (stratum[i] as f64 + uniform01(seed, factor, i)) / n as f64)
                .collect()
        }
    }
}

/// One dimension of the crossing: the factors it moves and their values, level by level.
#[derive(Debug, Clone)]
struct Dimension {
    factors: Vec<usize>,
    levels: usize,
    /// `values[l * factors.len() + j]` is the value of `factors[j]` at level l.
    values: Vec<f64>,
}

impl Dimension {
    fn level(&self, l: usize) -> &[f64] {
        let k = self.factors.len();
        &self.values[l * k..(l + 1) * k]
    }
}

/// The number of values of a factor.
fn level_count(spec: &CampaignSpec, f: &Factor) -> usize {
    match &f.levels {
        Levels::Grid(v) => v.len(),
        _ => spec.sampling.samples,
    }
}

/// Every value of a factor (random factors: its samples).
fn factor_values(spec: &CampaignSpec, f: &Factor) -> Vec<f64> {
    use statrs::distribution::ContinuousCDF;
    match &f.levels {
        Levels::Grid(v) => v.clone(),
        Levels::Uniform { low, high } => unit_samples(spec, &f.name)
            .into_iter()
            .map(|u| low + u * (high - low))
            .collect(),
        Levels::Normal { mean, std } => {
            let normal = statrs::distribution::Normal::new(0.0, 1.0).expect("standard normal");
            unit_samples(spec, &f.name)
                .into_iter()
                .map(|u| mean + std * normal.inverse_cdf(u))
                .collect()
        }
    }
}

/// The dimensions without their values: the factors each moves, in order of first appearance,
/// with its number of levels (zipped factors must have equal lengths).
fn layout(spec: &CampaignSpec) -> Result<Vec<Dimension>> {
    let mut dims: Vec<Dimension> = Vec::new();
    let mut zip_dim: Vec<(&str, usize)> = Vec::new();
    let mut random_dim: Option<usize> = None;
    for (fi, f) in spec.factors.iter().enumerate() {
        let n = level_count(spec, f);
        let existing = match (&f.zip, f.levels.is_random()) {
            (_, true) => random_dim,
            (Some(z), false) => zip_dim.iter().find(|(n, _)| n == z).map(|(_, d)| *d),
            (None, false) => None,
        };
        if let Some(d) = existing {
            if dims[d].levels != n {
                return Err(Error::Other(format!(
                    "campaign {}: factor '{}' has {n} values but the factors it is zipped with have {}",
                    spec.source.display(),
                    f.name,
                    dims[d].levels
                )));
            }
            dims[d].factors.push(fi);
            continue;
        }
        match (&f.zip, f.levels.is_random()) {
            (_, true) => random_dim = Some(dims.len()),
            (Some(z), false) => zip_dim.push((z, dims.len())),
            (None, false) => {}
        }
        dims.push(Dimension {
            factors: vec![fi],
            levels: n,
            values: Vec::new(),
        });
    }
    Ok(dims)
}

/// Fills the dimensions' values (after the counts were checked against the limits).
fn fill(spec: &CampaignSpec, dims: &mut [Dimension]) {
    for d in dims {
        let k = d.factors.len();
        d.values = vec![0.0; d.levels * k];
        for (j, &fi) in d.factors.iter().enumerate() {
            for (l, v) in factor_values(spec, &spec.factors[fi])
                .into_iter()
                .enumerate()
            {
                d.values[l * k + j] = v;
            }
        }
    }
}

/// A count for a message: the number, or "more than 10^38" when it does not fit.
fn count_text(n: Option<u128>) -> String {
    n.map_or_else(|| "more than 10^38".into(), |n| n.to_string())
}

/// Refuses a design with more than [`MAX_RUNS`] points or runs, from the counts alone.
fn check_counts(spec: &CampaignSpec, dims: &[Dimension], reps: u32, arms: usize) -> Result<()> {
    let points = dims
        .iter()
        .try_fold(1u128, |n, d| n.checked_mul(d.levels as u128));
    let runs = points.and_then(|p| p.checked_mul(reps as u128 * arms as u128));
    let max = MAX_RUNS as u128;
    let levels: Vec<String> = dims.iter().map(|d| d.levels.to_string()).collect();
    let (what, count, how) = if points.is_none_or(|p| p > max) {
        (
            "design points",
            points,
            format!("{} levels crossed", levels.join(" × ")),
        )
    } else if runs.is_none_or(|r| r > max) {
        let how = format!(
            "{} points × {reps} replications × {arms} arms",
            points.unwrap_or(0)
        );
        ("runs", runs, how)
    } else {
        return Ok(());
    };
    Err(Error::Other(format!(
        "campaign {}: {} {what} ({how}), more than the {MAX_RUNS} a campaign may have: the \
         journal and the tables of a finished campaign hold every run in memory (see the limits \
         in docs/campaigns.md); split it into several campaign files",
        spec.source.display(),
        count_text(count)
    )))
}

/// The design points: `points[p][f]` is factor f's value at point p. Every point at once: for
/// small designs and tests ([`Design::point`] gives one).
pub fn design_points(spec: &CampaignSpec) -> Result<Vec<Vec<f64>>> {
    let d = Design::unchecked(spec, "")?;
    Ok((0..d.points()).map(|p| d.point(p)).collect())
}

/// The runs of a campaign (design points × replications × arms), each computed from its index
/// when asked for: a campaign of any size takes the memory of its factors' levels, not of its
/// runs.
#[derive(Debug, Clone)]
pub struct Design {
    dims: Vec<Dimension>,
    points: usize,
    replications: u32,
    arms: usize,
    seed: u64,
    common: Vec<(String, Value)>,
    /// Each factor's (variable, scale).
    factors: Vec<(String, f64)>,
    seed_params: Vec<String>,
    arm_sets: Vec<Vec<(String, Value)>>,
    /// What every run key hashes first: the base inputs' hash, the stop and warm-up times.
    key_head: String,
}

impl Design {
    /// The design of a campaign file; `base_hash` identifies the base system and its FMUs (see
    /// [`super::Campaign`]). Refuses more than [`MAX_RUNS`] points or runs before it allocates
    /// anything for them, and two runs that set the same values.
    pub fn new(spec: &CampaignSpec, base_hash: &str) -> Result<Design> {
        let design = Design::unchecked(spec, base_hash)?;
        match design.duplicate() {
            Some((a, b)) => Err(Error::Other(format!(
                "campaign {}: runs {a} and {b} set the same values (identical factor values or arms?)",
                spec.source.display(),
            ))),
            None => Ok(design),
        }
    }

    /// The design without the check for runs that set the same values.
    fn unchecked(spec: &CampaignSpec, base_hash: &str) -> Result<Design> {
        let mut dims = layout(spec)?;
        let replications = spec.replications.count.max(1);
        let arms = spec.arms.len().max(1);
        check_counts(spec, &dims, replications, arms)?;
        fill(spec, &mut dims);
        Ok(Design {
            points: dims.iter().map(|d| d.levels).product(),
            dims,
            replications,
            arms,
            seed: spec.seed,
            common: spec.set.clone(),
            factors: spec
                .factors
                .iter()
                .map(|f| (f.variable.clone(), f.scale))
                .collect(),
            seed_params: spec.replications.seeds.clone(),
            arm_sets: spec.arms.iter().map(|a| a.set.clone()).collect(),
            key_head: format!(
                "shipsim-run-v1\n{base_hash}\nstop={:?}\nfork={:?}\n",
                spec.stop_time, spec.fork_at
            ),
        })
    }

    /// The number of runs.
    pub fn len(&self) -> usize {
        self.points * self.replications as usize * self.arms
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The number of design points.
    pub fn points(&self) -> usize {
        self.points
    }

    /// The index of the run of (point, replication, arm).
    pub fn index(&self, point: usize, replication: u32, arm: usize) -> usize {
        (point * self.replications as usize + replication as usize) * self.arms + arm
    }

    /// The factor values of design point `p` (before the factors' scales), in factor order.
    pub fn point(&self, p: usize) -> Vec<f64> {
        let mut values = vec![0.0; self.factors.len()];
        let mut rest = p;
        for d in self.dims.iter().rev() {
            let l = rest % d.levels;
            rest /= d.levels;
            for (&fi, &x) in d.factors.iter().zip(d.level(l)) {
                values[fi] = x;
            }
        }
        values
    }

    /// The derived seeds of replication `r`, in the order of `replications.seeds`.
    pub fn seeds(&self, r: u32) -> Vec<i64> {
        let seed = self.seed;
        self.seed_params
            .iter()
            .map(|p| derived_seed(seed, p, r))
            .collect()
    }

    /// Run `index`, or None past the last run.
    pub fn get(&self, index: usize) -> Option<Run> {
        (index < self.len()).then(|| self.run(index))
    }

    /// (point, replication, arm) of run `index`.
    pub fn place(&self, index: usize) -> (usize, u32, usize) {
        let arm = index % self.arms;
        let replication = ((index / self.arms) % self.replications as usize) as u32;
        (
            index / self.arms / self.replications as usize,
            replication,
            arm,
        )
    }

    /// Factor `f`'s value at design point `p` (before its scale).
    pub fn factor(&self, p: usize, f: usize) -> f64 {
        let mut rest = p;
        for d in self.dims.iter().rev() {
            let l = rest % d.levels;
            if let Some(j) = d.factors.iter().position(|&fi| fi == f) {
                return d.level(l)[j];
            }
            rest /= d.levels;
        }
        panic!("no factor {f}")
    }

    /// The seed of the `j`th seed parameter in replication `r`.
    pub fn seed(&self, r: u32, j: usize) -> i64 {
        derived_seed(self.seed, &self.seed_params[j], r)
    }

    /// Run `index` (< [`Design::len`]).
    pub fn run(&self, index: usize) -> Run {
        assert!(index < self.len(), "run {index} of {}", self.len());
        let (point, replication, arm) = self.place(index);
        let factors = self.point(point);
        let seeds = self.seeds(replication);
        let sets = self.sets(&factors, &seeds, arm);
        let key = self.key(&sets);
        Run {
            index,
            point,
            replication,
            arm,
            factors,
            seeds,
            sets,
            key,
        }
    }

    /// Every variable some run sets (a variable may be named more than once).
    pub fn variables(&self) -> impl Iterator<Item = &str> {
        let common = self.common.iter().map(|(v, _)| v.as_str());
        let factors = self.factors.iter().map(|(v, _)| v.as_str());
        let arms = self.arm_sets.iter().flatten().map(|(v, _)| v.as_str());
        common
            .chain(factors)
            .chain(self.seed_params.iter().map(String::as_str))
            .chain(arms)
    }

    /// Every run, in index order, each made when the iterator reaches it.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = Run> + '_ {
        (0..self.len()).map(|i| self.run(i))
    }

    /// Every value a run sets: common sets, factors (scaled), seeds, arm sets.
    fn sets(&self, factors: &[f64], seeds: &[i64], arm: usize) -> Vec<(String, Value)> {
        let mut sets = self.common.clone();
        for ((variable, scale), x) in self.factors.iter().zip(factors) {
            sets.push((variable.clone(), Value::Text(number_text(x * scale))));
        }
        for (p, s) in self.seed_params.iter().zip(seeds) {
            sets.push((p.clone(), Value::Integer(*s)));
        }
        if let Some(a) = self.arm_sets.get(arm) {
            sets.extend(a.iter().cloned());
        }
        sets
    }

    fn key(&self, sets: &[(String, Value)]) -> String {
        let mut h = Sha256::new();
        h.update(self.key_head.as_bytes());
        for (k, v) in effective_sets(sets) {
            h.update(format!("{k}={}\n", canonical(&v)).as_bytes());
        }
        hex(&h.finalize())
    }
}

/// The sets with later values winning, sorted by variable.
pub fn effective_sets(sets: &[(String, Value)]) -> Vec<(String, Value)> {
    let mut m = std::collections::BTreeMap::new();
    for (k, v) in sets {
        m.insert(k.clone(), v.clone());
    }
    m.into_iter().collect()
}

/// A number as the text `--set` takes: whole numbers without a fraction (so that Integer,
/// Enumeration and Boolean variables take them), others in shortest round-trip form.
fn number_text(x: f64) -> String {
    if x.fract() == 0.0 && x.abs() < 2f64.powi(53) {
        format!("{}", x as i64)
    } else {
        format!("{x:?}")
    }
}

/// A value's text for hashing: the same value always hashes the same, whatever its spelling.
fn canonical(v: &Value) -> String {
    match v {
        Value::Real(x) => number_text(*x),
        Value::Integer(i) => format!("{i}"),
        Value::Boolean(b) => format!("{}", *b as i32),
        Value::String(s) => format!("{s:?}"),
        Value::Text(t) => match t.as_str() {
            "true" => "1".into(),
            "false" => "0".into(),
            t => t
                .parse::<f64>()
                .map(number_text)
                .unwrap_or_else(|_| format!("{t:?}")),
        },
    }
}

pub fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}
