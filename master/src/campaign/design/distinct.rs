//! Two runs that set the same values have the same key, and resume could not tell them apart:
//! such a campaign is refused. The check is exact, and for the usual campaign makes no run.
//!
//! A run sets C(arm) ∪ F(point) ∪ S(replication): the common and arm values of the variables
//! that no factor or seed sets; the factors' values (a factor whose variable a later factor or
//! a seed also sets is overridden, so not part of F); the seeds. When no arm sets a factor's or
//! a seed's variable, the three parts set disjoint variables in every run, so two runs are
//! equal exactly when all three parts are: the design has two equal runs exactly when two arms
//! have equal C, two replications equal seeds, or two levels of one dimension equal values of
//! F (a point is one level of every dimension). Each is checked alone, by sorting: the seeds
//! take 4 bytes per seed and replication, the levels 8 bytes per factor and level.
//!
//! When an arm overrides a factor or a seed, every run's key is computed once, the first 8
//! bytes of each sorted (8 bytes per run), and a repeated prefix is confirmed by the full keys.

use super::{canonical, effective_sets, Design, Dimension};
use rayon::prelude::*;
use std::collections::{HashMap, HashSet};

impl Design {
    /// Two runs (by index, the first smaller) that set the same values, if there are any.
    pub(super) fn duplicate(&self) -> Option<(usize, usize)> {
        if self.arms_override() {
            return self.scanned_duplicate();
        }
        self.arm_duplicate()
            .or_else(|| self.seed_duplicate())
            .or_else(|| self.point_duplicate())
    }

    /// The variables that factors and seeds set.
    fn varied(&self) -> HashSet<&str> {
        let factors = self.factors.iter().map(|(v, _)| v.as_str());
        factors
            .chain(self.seed_params.iter().map(String::as_str))
            .collect()
    }

    /// Whether an arm sets a variable that a factor or a seed sets.
    fn arms_override(&self) -> bool {
        let varied = self.varied();
        let mut arm_variables = self.arm_sets.iter().flatten().map(|(v, _)| v.as_str());
        arm_variables.any(|v| varied.contains(v))
    }

    /// Two arms whose values, with the common values, are the same (C above).
    fn arm_duplicate(&self) -> Option<(usize, usize)> {
        let varied = self.varied();
        let mut seen: HashMap<Vec<(String, String)>, usize> = HashMap::new();
        for (arm, sets) in self.arm_sets.iter().enumerate() {
            let all: Vec<_> = self.common.iter().chain(sets).cloned().collect();
            let values = effective_sets(&all)
                .into_iter()
                .filter(|(v, _)| !varied.contains(v.as_str()))
                .map(|(v, x)| (v, canonical(&x)))
                .collect();
            if let Some(first) = seen.insert(values, arm) {
                return Some((self.index(0, 0, first), self.index(0, 0, arm)));
            }
        }
        None
    }

    /// Two replications with the same seeds (all of them when there are no seeds).
    fn seed_duplicate(&self) -> Option<(usize, usize)> {
        let seeds: Vec<u32> = (0..self.replications)
            .into_par_iter()
            .flat_map_iter(|r| self.seeds(r).into_iter().map(|s| s as u32))
            .collect();
        let (a, b) = equal_rows(&seeds, self.seed_params.len(), self.replications as usize)?;
        Some((self.index(0, a as u32, 0), self.index(0, b as u32, 0)))
    }

    /// Two design points that set the same factor values (F above): two levels of one
    /// dimension, the other dimensions at their first level.
    fn point_duplicate(&self) -> Option<(usize, usize)> {
        if self.points == 0 {
            return None;
        }
        let mut stride = self.points;
        for d in &self.dims {
            stride /= d.levels;
            if let Some((a, b)) = self.level_duplicate(d) {
                return Some((self.index(a * stride, 0, 0), self.index(b * stride, 0, 0)));
            }
        }
        None
    }

    /// Two levels of a dimension with the same values of its factors that are not overridden,
    /// as the keys see them (scaled).
    fn level_duplicate(&self, d: &Dimension) -> Option<(usize, usize)> {
        let shown: Vec<usize> = (0..d.factors.len())
            .filter(|&j| self.shown(d.factors[j]))
            .collect();
        let values: Vec<u64> = (0..d.levels)
            .flat_map(|l| {
                let level = d.level(l);
                shown
                    .iter()
                    .map(move |&j| key_bits(level[j] * self.factors[d.factors[j]].1))
            })
            .collect();
        equal_rows(&values, shown.len(), d.levels)
    }

    /// Whether factor `fi`'s value is in the runs' values: no later factor and no seed sets
    /// its variable.
    fn shown(&self, fi: usize) -> bool {
        let v = &self.factors[fi].0;
        !self.seed_params.contains(v) && !self.factors[fi + 1..].iter().any(|(w, _)| w == v)
    }

    /// Every run's key computed (in parallel): two runs with the same key.
    fn scanned_duplicate(&self) -> Option<(usize, usize)> {
        let prefix = |key: &str| u64::from_str_radix(&key[..16], 16).expect("a hex key");
        let mut prefixes: Vec<u64> = (0..self.len())
            .into_par_iter()
            .map(|i| prefix(&self.run(i).key))
            .collect();
        prefixes.par_sort_unstable();
        let repeated: HashSet<u64> = prefixes
            .windows(2)
            .filter(|w| w[0] == w[1])
            .map(|w| w[0])
            .collect();
        drop(prefixes);
        if repeated.is_empty() {
            return None;
        }
        let mut first: HashMap<String, usize> = HashMap::new();
        self.iter()
            .filter(|r| repeated.contains(&prefix(&r.key)))
            .find_map(|r| first.insert(r.key, r.index).map(|a| (a, r.index)))
    }
}

/// A number as the run keys see it (`number_text`): -0 is 0, and every NaN is one.
fn key_bits(x: f64) -> u64 {
    match x.is_nan() {
        true => f64::NAN.to_bits(),
        false => (x + 0.0).to_bits(),
    }
}

/// Two equal rows (by index, the first smaller) of the `n` rows of `k` numbers in `flat`, found
/// by sorting.
fn equal_rows<T: Ord + Sync>(flat: &[T], k: usize, n: usize) -> Option<(usize, usize)> {
    let row = |i: usize| &flat[i * k..(i + 1) * k];
    let mut order: Vec<usize> = (0..n).collect();
    order.par_sort_unstable_by(|&a, &b| row(a).cmp(row(b)).then(a.cmp(&b)));
    let w = order.windows(2).find(|w| row(w[0]) == row(w[1]))?;
    Some((w[0], w[1]))
}

#[cfg(test)]
mod tests {
    use super::super::{CampaignSpec, Design};
    use std::collections::HashSet;
    use std::path::Path;

    /// A small random number generator (xorshift), so that the cases are the same every time.
    struct Rng(u64);

    impl Rng {
        fn below(&mut self, n: usize) -> usize {
            self.0 ^= self.0 << 13;
            self.0 ^= self.0 >> 7;
            self.0 ^= self.0 << 17;
            (self.0 % n as u64) as usize
        }

        fn pick<'a>(&mut self, xs: &[&'a str]) -> &'a str {
            xs[self.below(xs.len())]
        }
    }

    const VARIABLES: [&str; 4] = ["m.a", "m.b", "m.c", "m.d"];
    const NUMBERS: [&str; 6] = ["0", "-0.0", "1", "1.0", "2", "0.5"];

    /// A campaign file with a few factors, seeds, arms and common values drawn from a few
    /// variables and numbers, so that runs with the same values are frequent.
    fn random_campaign(rng: &mut Rng) -> String {
        let mut text = String::from("system = \"s.toml\"\n");
        let set = |rng: &mut Rng| {
            let v = rng.pick(&VARIABLES);
            format!("\"{v}\" = {}", rng.pick(&NUMBERS))
        };
        if rng.below(2) == 0 {
            text += &format!("set = {{ {} }}\n", set(rng));
        }
        for f in 0..rng.below(4) {
            let values: Vec<&str> = (0..1 + rng.below(3)).map(|_| rng.pick(&NUMBERS)).collect();
            let zip = match rng.below(3) {
                0 => "zip = \"z\"\n",
                _ => "",
            };
            text += &format!(
                "[[factors]]\nname = \"f{f}\"\nvariable = \"{}\"\nvalues = [{}]\nscale = {}\n{zip}",
                rng.pick(&VARIABLES),
                values.join(", "),
                rng.pick(&["1", "0", "2"]),
            );
        }
        if rng.below(2) == 0 {
            let seeds: Vec<String> = (0..rng.below(2) + 1)
                .map(|_| format!("\"{}\"", rng.pick(&VARIABLES)))
                .collect::<HashSet<_>>()
                .into_iter()
                .collect();
            text += &format!(
                "[replications]\ncount = {}\nseeds = [{}]\n",
                1 + rng.below(3),
                seeds.join(", ")
            );
        }
        for a in 0..rng.below(4) {
            let sets: Vec<String> = (0..rng.below(3)).map(|_| set(rng)).collect();
            text += &format!(
                "[[arms]]\nname = \"a{a}\"\nset = {{ {} }}\n",
                sets.join(", ")
            );
        }
        text + "[[kpis]]\nname = \"k\"\nvariable = \"m.y\"\nstat = \"mean\"\n"
    }

    /// Whether two runs have the same key, from every key.
    fn brute_force(d: &Design) -> bool {
        let keys: HashSet<String> = d.iter().map(|r| r.key).collect();
        keys.len() < d.len()
    }

    #[test]
    fn the_check_for_equal_runs_agrees_with_comparing_every_key() {
        let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
        let (mut checked, mut equal, mut scanned) = (0, 0, 0);
        for case in 0..3000 {
            let text = random_campaign(&mut rng);
            // files the campaign reader refuses (a name clash, a zip of unequal lengths) or
            // zips of unequal lengths are not designs
            let Ok(spec) = CampaignSpec::parse(Path::new("c.toml"), &text) else {
                continue;
            };
            let Ok(d) = Design::unchecked(&spec, "h") else {
                continue;
            };
            let found = d.duplicate();
            assert_eq!(found.is_some(), brute_force(&d), "case {case}:\n{text}");
            if let Some((a, b)) = found {
                assert!(
                    a < b && d.run(a).key == d.run(b).key,
                    "case {case}:\n{text}"
                );
                equal += 1;
            }
            assert_eq!(d.scanned_duplicate().is_some(), found.is_some(), "{text}");
            scanned += d.arms_override() as usize;
            checked += 1;
        }
        // the cases cover both outcomes and both ways of checking
        assert!(
            checked > 1000 && equal > 100 && checked - equal > 100,
            "{checked} {equal}"
        );
        assert!(
            scanned > 100 && checked - scanned > 100,
            "{checked} {scanned}"
        );
    }
}
