//! Timing with its noise, shared by `termrast bench accuracy` and `termrast bench
//! effects`.
//!
//! Every row is timed in rounds. A round runs the row's work once, or several times
//! when one run is shorter than [`Policy::min_round`], and records the mean time of one
//! run. The rows being compared are timed in interleaved rounds (a round of every row,
//! then the next round), so a slow phase of a shared machine falls on all of them
//! rather than on whichever row was being timed at the moment.
//!
//! A row gets at least [`Policy::min_rounds`] rounds and then more until the 95 %
//! confidence interval of its median is within ± [`Policy::target_spread`] of the
//! median, or [`Policy::budget`] has been spent on it. The interval comes from order
//! statistics (distribution-free: nothing is assumed about the shape of the noise): for
//! `n` rounds sorted, `[x_j, x_{n+1−j}]` with the largest `j` whose coverage
//! `1 − 2·P(Bin(n, ½) < j)` is at least 95 %. Below 6 rounds no such `j` exists and
//! the interval is the minimum–maximum (94 % for 5 rounds).
//!
//! Two rows differ only when their intervals do not overlap; otherwise the difference
//! is [`Comparison::WithinNoise`].

use std::time::{Duration, Instant};

/// When to stop timing a row.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Policy {
    /// Rounds every row gets, however quiet the machine.
    pub min_rounds: usize,
    /// Rounds after which a row stops whatever its spread.
    pub max_rounds: usize,
    /// A row stops once its interval is within ± this fraction of its median...
    pub target_spread: f64,
    /// ...or once this much time has been spent timing it (rounds only, not the
    /// warm-up).
    pub budget: Duration,
    /// Shortest round: shorter runs are repeated within a round, so microsecond
    /// workloads are not lost in timer and scheduler noise.
    pub min_round: Duration,
}

impl Policy {
    /// At least `min_rounds`, then until ± `target_spread` or `budget`; rounds of at
    /// least 0.5 ms (short, so that on a busy machine most rounds run unpreempted and
    /// many fit in the budget), at most 1000 of them.
    #[must_use]
    pub fn new(min_rounds: usize, target_spread: f64, budget: Duration) -> Self {
        Self {
            min_rounds: min_rounds.max(1),
            max_rounds: 1000,
            target_spread,
            budget,
            min_round: Duration::from_micros(500),
        }
    }

    /// Whether a row with these round times, after `spent` timing it, is done.
    #[must_use]
    pub fn done(&self, samples: &[f64], spent: Duration) -> bool {
        let n = samples.len();
        n >= self.max_rounds.max(self.min_rounds)
            || (n >= self.min_rounds
                && (spent >= self.budget
                    || Timing::from_samples(samples).spread() <= self.target_spread))
    }
}

/// A measured time: the median of the rounds and the 95 % interval of that median.
/// Units are the caller's (nanoseconds from [`measure_each`]).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Timing {
    pub median: f64,
    /// The interval of the median: `low ≤ median ≤ high`.
    pub low: f64,
    pub high: f64,
    /// Rounds it was measured over.
    pub rounds: usize,
}

/// How a time compares with its baseline's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Comparison {
    /// The intervals overlap: the difference is not told apart from noise.
    WithinNoise,
    /// Slower than the baseline beyond the noise.
    Slower,
    /// Faster than the baseline beyond the noise.
    Faster,
}

/// 1-based rank `j` of the lower end of the 95 % order-statistic interval of the
/// median of `n` values: the largest `j` with `P(Bin(n, ½) ≤ j − 1) ≤ 2.5 %`, at least
/// 1 (below 6 values no rank reaches 95 % and the interval is the minimum–maximum).
#[must_use]
pub fn interval_rank(n: usize) -> usize {
    if n > 1000 {
        // Normal approximation (0.5^n underflows further on).
        let n = n as f64;
        return ((n - 1.96 * n.sqrt()) / 2.0).floor().max(1.0) as usize;
    }
    let mut pmf = 0.5f64.powi(n as i32);
    let mut cdf = pmf;
    let mut k = 0;
    while cdf <= 0.025 && k < n {
        k += 1;
        pmf *= (n - k + 1) as f64 / k as f64;
        cdf += pmf;
    }
    // Now P(B ≤ k) > 2.5 % and P(B ≤ k − 1) ≤ 2.5 %: j − 1 = k − 1.
    k.max(1)
}

impl Timing {
    /// The median of `samples` and its interval (all zero for no samples).
    #[must_use]
    pub fn from_samples(samples: &[f64]) -> Self {
        let n = samples.len();
        if n == 0 {
            return Self::default();
        }
        let mut s = samples.to_vec();
        s.sort_by(f64::total_cmp);
        let median = if n % 2 == 1 {
            s[n / 2]
        } else {
            (s[n / 2 - 1] + s[n / 2]) / 2.0
        };
        let j = interval_rank(n).min(n.div_ceil(2));
        Self {
            median,
            low: s[j - 1],
            high: s[n - j],
            rounds: n,
        }
    }

    /// The relative half-width of the interval: the larger distance from the median
    /// to an end, over the median.
    #[must_use]
    pub fn spread(&self) -> f64 {
        if self.median > 0.0 {
            (self.median - self.low).max(self.high - self.median) / self.median
        } else {
            0.0
        }
    }

    /// The spread as printed: `±4%`, `±0.7%`.
    #[must_use]
    pub fn spread_label(&self) -> String {
        let pct = self.spread() * 100.0;
        if pct < 9.95 {
            format!("±{pct:.1}%")
        } else {
            format!("±{pct:.0}%")
        }
    }

    /// Every value times `k` (units, per-triangle figures).
    #[must_use]
    pub fn scaled(&self, k: f64) -> Self {
        Self {
            median: self.median * k,
            low: self.low * k,
            high: self.high * k,
            rounds: self.rounds,
        }
    }

    /// The time of both, one after the other: medians and interval ends add (the
    /// interval of the sum is taken as wide as the sum of the intervals), rounds are
    /// the fewer of the two (`other` alone if this one is empty).
    #[must_use]
    pub fn plus(&self, other: &Self) -> Self {
        if self.rounds == 0 {
            return *other;
        }
        Self {
            median: self.median + other.median,
            low: self.low + other.low,
            high: self.high + other.high,
            rounds: self.rounds.min(other.rounds),
        }
    }

    /// This time against a baseline's: within noise when the intervals overlap.
    #[must_use]
    pub fn compare(&self, base: &Self) -> Comparison {
        if self.low <= base.high && base.low <= self.high {
            Comparison::WithinNoise
        } else if self.median > base.median {
            Comparison::Slower
        } else {
            Comparison::Faster
        }
    }
}

/// Times `run(i)` for every `i < n` in interleaved rounds until each is done by
/// `policy`, and returns the time of one run of each, in nanoseconds. Each `i` gets an
/// untimed warm-up run and a timed one that sets how many runs make up its rounds.
pub fn measure_each(policy: &Policy, n: usize, mut run: impl FnMut(usize)) -> Vec<Timing> {
    let min_round = policy.min_round.as_secs_f64() * 1e9;
    let inner: Vec<u32> = (0..n)
        .map(|i| {
            run(i);
            let start = Instant::now();
            run(i);
            let once = start.elapsed().as_secs_f64() * 1e9;
            (min_round / once.max(1.0)).ceil().clamp(1.0, 100_000.0) as u32
        })
        .collect();
    let mut samples: Vec<Vec<f64>> = vec![Vec::new(); n];
    let mut spent = vec![Duration::ZERO; n];
    let mut active: Vec<usize> = (0..n).collect();
    while !active.is_empty() {
        for &i in &active {
            let start = Instant::now();
            for _ in 0..inner[i] {
                run(i);
            }
            let elapsed = start.elapsed();
            spent[i] += elapsed;
            samples[i].push(elapsed.as_secs_f64() * 1e9 / f64::from(inner[i]));
        }
        active.retain(|&i| !policy.done(&samples[i], spent[i]));
    }
    samples.iter().map(|s| Timing::from_samples(s)).collect()
}

/// [`measure_each`] for one piece of work.
pub fn measure(policy: &Policy, mut run: impl FnMut()) -> Timing {
    measure_each(policy, 1, |_| run())[0]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn timing(median: f64, low: f64, high: f64) -> Timing {
        Timing {
            median,
            low,
            high,
            rounds: 5,
        }
    }

    #[test]
    fn interval_ranks_match_the_binomial_table() {
        // Ranks of the 95 % interval of the median (e.g. Conover, table A3).
        for (n, j) in [(1, 1), (5, 1), (6, 1), (8, 1), (9, 2), (20, 6), (100, 40)] {
            assert_eq!(interval_rank(n), j, "n = {n}");
        }
        let big = interval_rank(2000);
        assert!((950..=960).contains(&big), "{big}");
    }

    #[test]
    fn median_interval_and_spread_of_synthetic_rounds() {
        let t = Timing::from_samples(&[10.0, 12.0, 9.0, 11.0, 30.0]);
        assert_eq!((t.median, t.low, t.high, t.rounds), (11.0, 9.0, 30.0, 5));
        assert!((t.spread() - 19.0 / 11.0).abs() < 1e-12);
        // With 20 rounds the outliers fall outside the interval (ranks 6 and 15).
        let mut s: Vec<f64> = (0..18).map(|k| 100.0 + f64::from(k % 6)).collect();
        s.extend([1.0, 1000.0]);
        let t = Timing::from_samples(&s);
        assert!(t.low >= 100.0 && t.high <= 105.0, "{t:?}");
        assert_eq!(timing(2.0, 1.9, 2.08).spread_label(), "±5.0%");
        assert_eq!(timing(2.0, 1.5, 2.0).spread_label(), "±25%");
        assert_eq!(Timing::from_samples(&[]), Timing::default());
    }

    #[test]
    fn overlapping_intervals_are_within_noise() {
        let base = timing(10.0, 9.5, 10.6);
        // A difference of 0.4 with intervals that overlap is noise, either way.
        assert_eq!(
            timing(10.4, 10.1, 11.0).compare(&base),
            Comparison::WithinNoise
        );
        assert_eq!(
            timing(9.6, 9.0, 9.9).compare(&base),
            Comparison::WithinNoise
        );
        // Touching ends still overlap.
        assert_eq!(
            timing(11.0, 10.6, 11.5).compare(&base),
            Comparison::WithinNoise
        );
        // Apart: slower or faster.
        assert_eq!(timing(11.0, 10.7, 11.5).compare(&base), Comparison::Slower);
        assert_eq!(timing(8.0, 7.5, 9.4).compare(&base), Comparison::Faster);
        // A wide baseline swallows a large difference of medians.
        let noisy = timing(10.0, 5.0, 20.0);
        assert_eq!(
            timing(15.0, 14.0, 16.0).compare(&noisy),
            Comparison::WithinNoise
        );
        // A row is within noise of itself.
        assert_eq!(base.compare(&base), Comparison::WithinNoise);
    }

    #[test]
    fn sums_add_medians_and_interval_ends() {
        let s = timing(1.0, 0.9, 1.2).plus(&Timing {
            rounds: 7,
            ..timing(2.0, 1.8, 2.1)
        });
        assert_eq!((s.median, s.low, s.high, s.rounds), (3.0, 2.7, 3.3, 5));
        assert_eq!(Timing::default().plus(&s), s);
        let ms = s.scaled(1e-3);
        assert!((ms.median - 3e-3).abs() < 1e-15 && ms.rounds == 5);
    }

    #[test]
    fn a_row_stops_at_its_spread_or_its_budget() {
        let p = Policy::new(5, 0.05, Duration::from_millis(100));
        let tight = [100.0, 101.0, 99.0, 100.0, 102.0];
        let wide = [100.0, 130.0, 80.0, 100.0, 102.0];
        let short = Duration::from_millis(10);
        assert!(!p.done(&tight[..4], short), "fewer than min_rounds");
        assert!(p.done(&tight, short));
        assert!(!p.done(&wide, short), "spread ±30% > 5%: more rounds");
        assert!(p.done(&wide, Duration::from_millis(100)), "budget spent");
        let capped = Policy { max_rounds: 5, ..p };
        assert!(capped.done(&wide, short));
    }

    #[test]
    fn measure_each_times_every_row_in_rounds() {
        let p = Policy {
            min_round: Duration::from_micros(50),
            ..Policy::new(4, 0.0, Duration::ZERO)
        };
        let mut calls = [0u32; 3];
        let t = measure_each(&p, 3, |i| {
            calls[i] += 1;
            std::hint::black_box((0..(i as u64 + 1) * 200).sum::<u64>());
        });
        assert_eq!(t.len(), 3);
        for (k, t) in t.iter().enumerate() {
            assert_eq!(t.rounds, 4, "row {k}: target 0 stops at the budget (0)");
            assert!(t.median > 0.0 && t.low <= t.median && t.median <= t.high);
            assert!(calls[k] >= 6, "warm-up, calibration and 4 rounds");
        }
        assert_eq!(measure(&p, || {}).rounds, 4);
    }
}
