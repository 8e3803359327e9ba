//! Comparison of labelled sets of scored trajectories: per-criterion mean,
//! variance and sum per set, the form of S0 Tab. 5.3–5.5.

use super::criteria::{Criterion, Scores};
use super::error::ScoreError;

/// Summary statistics of one criterion over one set.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stat {
    /// Number of values.
    pub count: usize,
    /// Arithmetic mean.
    pub mean: f64,
    /// Sample variance `Σ (x − mean)² / (count − 1)` (Bessel-corrected, the
    /// default of pandas and R); `None` for a single value. S0 Tab. 5.4–5.5
    /// ("Rozptyl") does not say which estimator it used.
    pub variance: Option<f64>,
    /// Population variance `Σ (x − mean)² / count`.
    pub population_variance: f64,
    /// Sum of the values (S0 Tab. 5.4–5.5 "Suma"; Tab. 5.3's entries).
    pub sum: f64,
    /// Smallest value.
    pub min: f64,
    /// Largest value.
    pub max: f64,
}

/// Mean, variances (Welford's update), compensated sum (Neumaier), min and
/// max of `values`; `None` when there are none.
///
/// ```
/// use kinplan_core::score::summarize;
/// let s = summarize([1.0, 2.0, 3.0, 4.0]).unwrap();
/// assert_eq!((s.mean, s.sum), (2.5, 10.0));
/// assert!((s.variance.unwrap() - 5.0 / 3.0).abs() < 1e-15);
/// assert!((s.population_variance - 1.25).abs() < 1e-15);
/// ```
pub fn summarize(values: impl IntoIterator<Item = f64>) -> Option<Stat> {
    let mut count = 0usize;
    let (mut mean, mut m2) = (0.0f64, 0.0f64);
    let (mut sum, mut comp) = (0.0f64, 0.0f64);
    let (mut min, mut max) = (f64::INFINITY, f64::NEG_INFINITY);
    for x in values {
        count += 1;
        let delta = x - mean;
        mean += delta / count as f64;
        m2 += delta * (x - mean);
        let t = sum + x;
        comp += if sum.abs() >= x.abs() {
            (sum - t) + x
        } else {
            (x - t) + sum
        };
        sum = t;
        min = min.min(x);
        max = max.max(x);
    }
    if count == 0 {
        return None;
    }
    Some(Stat {
        count,
        mean,
        variance: (count > 1).then(|| m2 / (count - 1) as f64),
        population_variance: m2 / count as f64,
        sum: sum + comp,
        min,
        max,
    })
}

/// One labelled set of scored trajectories (e.g. all runs of one planner).
#[derive(Debug, Clone, Copy)]
pub struct LabelledSet<'a> {
    /// The set's name ("RRTConnect", "STOMP", "CCSTOMP", …).
    pub label: &'a str,
    /// Scores of its trajectories.
    pub scores: &'a [Scores],
}

/// Statistics of one set.
#[derive(Debug, Clone, PartialEq)]
pub struct SetSummary {
    /// The set's label.
    pub label: String,
    /// Number of trajectories.
    pub trajectories: usize,
    /// One entry per criterion that every trajectory of the set has (RDM only
    /// when all were scored with robot points, the cycle time only when all had
    /// limits), in [`Criterion::ALL`] order.
    pub stats: Vec<(Criterion, Stat)>,
}

impl SetSummary {
    /// Statistics of criterion `c`, if every trajectory had it.
    pub fn get(&self, c: Criterion) -> Option<&Stat> {
        self.stats.iter().find(|(k, _)| *k == c).map(|(_, s)| s)
    }
}

/// Statistics of every set, in input order: S0 Tab. 5.4/5.5 are the rows
/// `(label, mean, variance, sum)` of one criterion, Tab. 5.3 the sums of
/// several.
#[derive(Debug, Clone, PartialEq)]
pub struct Comparison {
    /// One summary per set.
    pub sets: Vec<SetSummary>,
}

impl Comparison {
    /// Statistics of criterion `c` in the set labelled `label`.
    pub fn get(&self, label: &str, c: Criterion) -> Option<&Stat> {
        self.sets.iter().find(|s| s.label == label)?.get(c)
    }
}

/// Compares labelled sets of scored trajectories: per set and criterion the
/// mean, sample variance and sum (S0 Tab. 5.3–5.5). Rejects an empty set and a
/// repeated label.
///
/// ```
/// use kinplan_core::score::{compare, Criterion, LabelledSet, Scores};
/// let a = [Scores { oc: 1.0, ..Default::default() }, Scores { oc: 3.0, ..Default::default() }];
/// let b = [Scores { oc: 0.5, ..Default::default() }];
/// let c = compare(&[LabelledSet { label: "rrt", scores: &a }, LabelledSet { label: "ccstomp", scores: &b }]).unwrap();
/// let oc = c.get("rrt", Criterion::Oc).unwrap();
/// assert_eq!((oc.mean, oc.variance, oc.sum), (2.0, Some(2.0), 4.0));
/// assert_eq!(c.get("ccstomp", Criterion::Oc).unwrap().variance, None);
/// ```
pub fn compare(sets: &[LabelledSet<'_>]) -> Result<Comparison, ScoreError> {
    let mut out = Vec::with_capacity(sets.len());
    for (k, set) in sets.iter().enumerate() {
        if sets[..k].iter().any(|s| s.label == set.label) {
            return Err(ScoreError::DuplicateLabel {
                label: set.label.to_owned(),
            });
        }
        if set.scores.is_empty() {
            return Err(ScoreError::EmptySet {
                label: set.label.to_owned(),
            });
        }
        let stats = Criterion::ALL
            .into_iter()
            .filter(|&c| set.scores.iter().all(|s| s.get(c).is_some()))
            .filter_map(|c| summarize(set.scores.iter().filter_map(|s| s.get(c))).map(|st| (c, st)))
            .collect();
        out.push(SetSummary {
            label: set.label.to_owned(),
            trajectories: set.scores.len(),
            stats,
        });
    }
    Ok(Comparison { sets: out })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistics_by_hand() {
        let s = summarize([2.0, 4.0, 4.0, 4.0, 5.0, 5.0, 7.0, 9.0]).unwrap();
        assert_eq!(s.count, 8);
        assert_eq!(s.mean, 5.0);
        assert_eq!(s.sum, 40.0);
        assert!((s.population_variance - 4.0).abs() < 1e-14);
        assert!((s.variance.unwrap() - 32.0 / 7.0).abs() < 1e-14);
        assert_eq!((s.min, s.max), (2.0, 9.0));
        assert!(summarize([]).is_none());
        let one = summarize([3.5]).unwrap();
        assert_eq!((one.variance, one.population_variance), (None, 0.0));
    }

    #[test]
    fn welford_is_stable_with_a_large_offset() {
        let s = summarize([1e9 + 4.0, 1e9 + 7.0, 1e9 + 13.0, 1e9 + 16.0]).unwrap();
        assert!((s.variance.unwrap() - 30.0).abs() < 1e-6);
    }

    #[test]
    fn optional_criteria_only_when_every_trajectory_has_them() {
        let a = [
            Scores {
                rdm: Some(1.0),
                cycle_time: Some(2.0),
                ..Default::default()
            },
            Scores {
                rdm: None,
                cycle_time: Some(4.0),
                ..Default::default()
            },
        ];
        let c = compare(&[LabelledSet {
            label: "a",
            scores: &a,
        }])
        .unwrap();
        assert!(c.get("a", Criterion::Rdm).is_none());
        assert_eq!(c.get("a", Criterion::CycleTime).unwrap().mean, 3.0);
        assert_eq!(c.sets[0].stats.len(), 12);
        assert_eq!(c.sets[0].trajectories, 2);
    }

    #[test]
    fn orders_planners_like_s0_tab_5_4() {
        // three planners; OC values chosen so CCSTOMP < STOMP < RRTConnect
        let mk = |v: &[f64]| {
            v.iter()
                .map(|&oc| Scores {
                    oc,
                    ..Default::default()
                })
                .collect::<Vec<_>>()
        };
        let (r, s, c) = (mk(&[6.0, 9.0, 4.0]), mk(&[5.0, 4.5]), mk(&[3.0, 4.0, 3.5]));
        let cmp = compare(&[
            LabelledSet {
                label: "RRTConnect",
                scores: &r,
            },
            LabelledSet {
                label: "STOMP",
                scores: &s,
            },
            LabelledSet {
                label: "CCSTOMP",
                scores: &c,
            },
        ])
        .unwrap();
        let labels: Vec<_> = cmp.sets.iter().map(|s| s.label.as_str()).collect();
        assert_eq!(labels, ["RRTConnect", "STOMP", "CCSTOMP"]);
        let mean = |l| cmp.get(l, Criterion::Oc).unwrap().mean;
        assert!(mean("CCSTOMP") < mean("STOMP") && mean("STOMP") < mean("RRTConnect"));
        assert_eq!(cmp.get("RRTConnect", Criterion::Oc).unwrap().sum, 19.0);
    }

    #[test]
    fn bad_sets_rejected() {
        let a = [Scores::default()];
        assert!(matches!(
            compare(&[LabelledSet { label: "x", scores: &[] }]),
            Err(ScoreError::EmptySet { label }) if label == "x"
        ));
        assert!(matches!(
            compare(&[LabelledSet { label: "x", scores: &a }, LabelledSet { label: "x", scores: &a }]),
            Err(ScoreError::DuplicateLabel { label }) if label == "x"
        ));
        assert_eq!(compare(&[]).unwrap().sets.len(), 0);
    }
}
