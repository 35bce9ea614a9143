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

use super::spec::{CampaignSpec, Levels, SamplingMethod, MAX_RUNS};
use crate::error::{Error, Result};
use crate::system::Value;
use sha2::{Digest, Sha256};

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

/// One dimension of the crossing: the factors it moves and their values per level.
struct Dimension {
    factors: Vec<usize>,
    /// `levels[l][j]` is the value of `factors[j]` at level l.
    levels: Vec<Vec<f64>>,
}

fn dimensions(spec: &CampaignSpec) -> Result<Vec<Dimension>> {
    let mut dims: Vec<Dimension> = Vec::new();
    let mut zip_dim: Vec<(String, usize)> = Vec::new();
    let mut random_dim: Option<usize> = None;
    let normal = statrs::distribution::Normal::new(0.0, 1.0).expect("standard normal");
    for (fi, f) in spec.factors.iter().enumerate() {
        let values: Vec<f64> = match &f.levels {
            Levels::Grid(v) => v.clone(),
            Levels::Uniform { low, high } => unit_samples(spec, &f.name)
                .into_iter()
                .map(|u| low + u * (high - low))
                .collect(),
            Levels::Normal { mean, std } => {
                use statrs::distribution::ContinuousCDF;
                unit_samples(spec, &f.name)
                    .into_iter()
                    .map(|u| mean + std * normal.inverse_cdf(u))
                    .collect()
            }
        };
        let existing = if f.levels.is_random() {
            random_dim
        } else {
            f.zip
                .as_ref()
                .and_then(|z| zip_dim.iter().find(|(n, _)| n == z).map(|(_, d)| *d))
        };
        match existing {
            Some(d) => {
                let dim = &mut dims[d];
                if dim.levels.len() != values.len() {
                    return Err(Error::Other(format!(
                        "campaign {}: factor '{}' has {} values but the factors it is zipped with have {}",
                        spec.source.display(),
                        f.name,
                        values.len(),
                        dim.levels.len()
                    )));
                }
                dim.factors.push(fi);
                for (l, v) in values.into_iter().enumerate() {
                    dim.levels[l].push(v);
                }
            }
            None => {
                if f.levels.is_random() {
                    random_dim = Some(dims.len());
                } else if let Some(z) = &f.zip {
                    zip_dim.push((z.clone(), dims.len()));
                }
                dims.push(Dimension {
                    factors: vec![fi],
                    levels: values.into_iter().map(|v| vec![v]).collect(),
                });
            }
        }
    }
    Ok(dims)
}

/// The design points: `points[p][f]` is factor f's value at point p.
pub fn design_points(spec: &CampaignSpec) -> Result<Vec<Vec<f64>>> {
    let dims = dimensions(spec)?;
    let total = dims
        .iter()
        .try_fold(1usize, |n, d| n.checked_mul(d.levels.len()))
        .filter(|n| *n <= MAX_RUNS)
        .ok_or_else(|| {
            Error::Other(format!(
                "campaign {}: more than {MAX_RUNS} design points",
                spec.source.display()
            ))
        })?;
    let mut points = Vec::with_capacity(total);
    for p in 0..total {
        let mut values = vec![0.0; spec.factors.len()];
        let mut rest = p;
        for d in dims.iter().rev() {
            let l = rest % d.levels.len();
            rest /= d.levels.len();
            for (j, &fi) in d.factors.iter().enumerate() {
                values[fi] = d.levels[l][j];
            }
        }
        points.push(values);
    }
    Ok(points)
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

/// Every run of the campaign, in index order. `base_hash` identifies the base system and its
/// FMUs (see [`super::Campaign`]).
pub fn runs(spec: &CampaignSpec, base_hash: &str) -> Result<Vec<Run>> {
    let points = design_points(spec)?;
    let reps = spec.replications.count.max(1);
    let arms = spec.arms.len().max(1);
    let total = points
        .len()
        .checked_mul(reps as usize)
        .and_then(|n| n.checked_mul(arms))
        .filter(|n| *n <= 100_000_000)
        .ok_or_else(|| {
            Error::Other(format!(
                "campaign {}: more than 10^8 runs",
                spec.source.display()
            ))
        })?;
    let mut out = Vec::with_capacity(total);
    for (point, values) in points.iter().enumerate() {
        for r in 0..reps {
            let seeds: Vec<i64> = spec
                .replications
                .seeds
                .iter()
                .map(|p| derived_seed(spec.seed, p, r))
                .collect();
            for arm in 0..arms {
                let mut sets = spec.set.clone();
                for (f, x) in spec.factors.iter().zip(values) {
                    sets.push((f.variable.clone(), Value::Text(number_text(x * f.scale))));
                }
                for (p, s) in spec.replications.seeds.iter().zip(&seeds) {
                    sets.push((p.clone(), Value::Integer(*s)));
                }
                if let Some(a) = spec.arms.get(arm) {
                    sets.extend(a.set.iter().cloned());
                }
                let key = run_key(spec, base_hash, &sets);
                out.push(Run {
                    index: out.len(),
                    point,
                    replication: r,
                    arm,
                    factors: values.clone(),
                    seeds: seeds.clone(),
                    sets,
                    key,
                });
            }
        }
    }
    let mut seen = std::collections::HashMap::new();
    for r in &out {
        if let Some(first) = seen.insert(&r.key, r.index) {
            return Err(Error::Other(format!(
                "campaign {}: runs {first} and {} set the same values (identical factor values or arms?)",
                spec.source.display(),
                r.index
            )));
        }
    }
    Ok(out)
}

/// The sets with later values winning, sorted by variable.
pub fn effective_sets(sets: &[(String, Value)]) -> Vec<(String, Value)> {
    let mut m = std::collections::BTreeMap::new();
    for (k, v) in sets {
        m.insert(k.clone(), v.clone());
    }
    m.into_iter().collect()
}

fn run_key(spec: &CampaignSpec, base_hash: &str, sets: &[(String, Value)]) -> String {
    let mut h = Sha256::new();
    h.update(b"shipsim-run-v1\n");
    h.update(base_hash.as_bytes());
    h.update(format!("\nstop={:?}\nfork={:?}\n", spec.stop_time, spec.fork_at).as_bytes());
    for (k, v) in effective_sets(sets) {
        h.update(format!("{k}={}\n", canonical(&v)).as_bytes());
    }
    hex(&h.finalize())
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
