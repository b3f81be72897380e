//! The sweep: every strategy rendered at every budget of the ladder, timed.
//! Renders are deterministic (same scene, seed and settings, same pixels), so a
//! budget's repeated runs differ only in time: the first run's image is kept.

use crate::budget::{Ladder, SampleBudget};
use crate::strategy::Strategy;
use crate::{BenchError, Progress, Setup};
use glam::Vec3;
use glint_integrator::RenderStats;
use std::time::Duration;

/// One strategy at one budget.
#[derive(Clone, Debug)]
pub struct Measurement {
    /// Index into the bench's strategies.
    pub strategy: usize,
    pub budget: SampleBudget,
    /// Rendering time of each run, in order (the first includes one-off work
    /// such as building MIP pyramids).
    pub times: Vec<Duration>,
    /// Rays of one run (every run traces the same).
    pub stats: RenderStats,
    /// The image, row-major from the top-left pixel, linear RGB.
    pub image: Vec<Vec3>,
}

impl Measurement {
    /// The median of the runs' times (the lower middle one for an even count).
    pub fn median_time(&self) -> Duration {
        let mut t = self.times.clone();
        t.sort();
        t[(t.len() - 1) / 2]
    }

    pub fn min_time(&self) -> Duration {
        self.times.iter().copied().min().unwrap_or_default()
    }

    pub fn max_time(&self) -> Duration {
        self.times.iter().copied().max().unwrap_or_default()
    }
}

/// Renders every strategy over the ladder.
pub fn run(
    setup: &Setup,
    strategies: &[Strategy],
    ladder: &Ladder,
    repeat: usize,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Vec<Measurement>, BenchError> {
    let mut counter = Counter::new(planned_renders(strategies.len(), ladder, repeat));
    let mut measurements = Vec::new();
    for (index, strategy) in strategies.iter().enumerate() {
        let budgets = match ladder {
            Ladder::Samples(budgets) => budgets.clone(),
            Ladder::Time {
                budgets,
                light_samples,
                environment_samples,
            } => {
                let base = SampleBudget {
                    spp: 1,
                    light_samples: *light_samples,
                    environment_samples: *environment_samples,
                };
                calibrated_budgets(setup, strategy, base, budgets, &mut counter, progress)?
            }
        };
        for budget in budgets {
            measurements.push(measure(
                setup,
                index,
                strategy,
                budget,
                repeat,
                &mut counter,
                progress,
            )?);
        }
    }
    Ok(measurements)
}

/// Renders one strategy at one budget `repeat` times.
fn measure(
    setup: &Setup,
    index: usize,
    strategy: &Strategy,
    budget: SampleBudget,
    repeat: usize,
    counter: &mut Counter,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Measurement, BenchError> {
    let (scene, settings) = setup.prepare(strategy, budget)?;
    let mut times = Vec::with_capacity(repeat);
    let mut first = None;
    for run in 0..repeat.max(1) {
        let what = format!(
            "{} at {} spp × {} light samples (run {} of {})",
            strategy.name(),
            budget.spp,
            budget.light_samples,
            run + 1,
            repeat.max(1)
        );
        let output = setup.render(&scene, &settings, counter.next(&what, progress), progress)?;
        times.push(output.stats.elapsed);
        first.get_or_insert(output);
    }
    let first = first.expect("at least one run");
    Ok(Measurement {
        strategy: index,
        budget,
        times,
        stats: first.stats,
        image: first.film.pixels().to_vec(),
    })
}

/// The sample budgets that render in about the given times with `strategy`:
/// a render at 1 and at 4 spp fits `time = a + b·spp`, each budget gets
/// `spp = (T − a)/b` rounded (to a square for the grid pattern), at least 1, and
/// budgets that come out equal are rendered once.
fn calibrated_budgets(
    setup: &Setup,
    strategy: &Strategy,
    base: SampleBudget,
    times: &[Duration],
    counter: &mut Counter,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Vec<SampleBudget>, BenchError> {
    let mut seconds = [0.0; 2];
    for (slot, spp) in [1u32, 4].into_iter().enumerate() {
        let budget = SampleBudget { spp, ..base };
        let (scene, settings) = setup.prepare(strategy, budget)?;
        let what = format!("{}: timing {spp} spp", strategy.name());
        let output = setup.render(&scene, &settings, counter.next(&what, progress), progress)?;
        seconds[slot] = output.stats.elapsed.as_secs_f64();
    }
    let per_spp = ((seconds[1] - seconds[0]) / 3.0)
        .max(seconds[1] / 4.0 * 0.05)
        .max(1e-9);
    let fixed = (seconds[0] - per_spp).max(0.0);
    let mut budgets: Vec<SampleBudget> = Vec::new();
    for t in times {
        let raw = ((t.as_secs_f64() - fixed) / per_spp)
            .round()
            .clamp(1.0, 1e6) as u32;
        let spp = if strategy.pixel == glint_integrator::SamplePattern::Grid {
            let k = (raw as f64).sqrt().round().max(1.0) as u32;
            k * k
        } else {
            raw
        };
        if budgets.last().is_none_or(|b| b.spp < spp) {
            budgets.push(SampleBudget { spp, ..base });
        }
    }
    Ok(budgets)
}

/// How many renders a sweep will do (time ladders add two timing renders per
/// strategy and may merge budgets, so this is an upper bound for them).
fn planned_renders(strategies: usize, ladder: &Ladder, repeat: usize) -> usize {
    let per_strategy = match ladder {
        Ladder::Samples(b) => b.len() * repeat.max(1),
        Ladder::Time { budgets, .. } => 2 + budgets.len() * repeat.max(1),
    };
    strategies * per_strategy
}

/// Numbers the renders for progress reports.
pub(crate) struct Counter {
    done: usize,
    pub(crate) total: usize,
}

impl Counter {
    pub(crate) fn new(total: usize) -> Self {
        Self { done: 0, total }
    }

    /// Announces the next render and returns its number (from 1).
    pub(crate) fn next(&mut self, what: &str, progress: &(dyn Fn(Progress) + Sync)) -> usize {
        self.done += 1;
        self.total = self.total.max(self.done);
        progress(Progress::Render {
            number: self.done,
            planned: self.total,
            what,
        });
        self.done
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_min_and_max_of_the_runs() {
        let m = Measurement {
            strategy: 0,
            budget: SampleBudget {
                spp: 1,
                light_samples: 1,
                environment_samples: 0,
            },
            times: [30, 10, 20, 40].map(Duration::from_millis).to_vec(),
            stats: RenderStats::default(),
            image: Vec::new(),
        };
        assert_eq!(m.median_time(), Duration::from_millis(20));
        assert_eq!(m.min_time(), Duration::from_millis(10));
        assert_eq!(m.max_time(), Duration::from_millis(40));
    }
}
