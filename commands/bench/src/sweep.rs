//! The sweep: every strategy rendered at every budget of the ladder, timed.
//!
//! Strategies take turns: budget by budget and run by run, each strategy renders
//! once before any renders again, so that the machine's drift in speed (tens of
//! percent from minute to minute on a shared machine) falls on all of them alike
//! and their ratios stay meaningful. Renders are deterministic (same scene, seed
//! and settings, same pixels), so a budget's repeated runs differ only in time:
//! the first run's image is kept.

use crate::budget::{Ladder, SampleBudget};
use crate::strategy::Strategy;
use crate::{BenchError, Progress, Setup};
use glam::Vec3;
use glint_integrator::{RenderSettings, RenderStats, Scene};
use std::time::Duration;

/// One strategy at one budget.
#[derive(Clone, Debug)]
pub struct Measurement {
    /// Index into the bench's strategies.
    pub strategy: usize,
    pub budget: SampleBudget,
    /// Rendering time of each run, in order (the strategy's very first run also
    /// pays one-off work such as building MIP pyramids).
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

/// One strategy's scene, base settings and budgets.
struct Contestant<'a> {
    index: usize,
    strategy: &'a Strategy,
    scene: Scene,
    settings: RenderSettings,
    budgets: Vec<SampleBudget>,
}

impl Contestant<'_> {
    fn settings_at(&self, budget: SampleBudget) -> Result<RenderSettings, BenchError> {
        let settings = RenderSettings {
            spp: budget.spp,
            light_samples: budget.light_samples,
            environment_samples: budget.environment_samples,
            ..self.settings.clone()
        };
        settings
            .validate()
            .map_err(|e| BenchError::Input(format!("{}: {e}", self.strategy.name())))?;
        Ok(settings)
    }
}

/// Renders every strategy over the ladder, strategies taking turns.
pub fn run(
    setup: &Setup,
    strategies: &[Strategy],
    ladder: &Ladder,
    repeat: usize,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Vec<Measurement>, BenchError> {
    let repeat = repeat.max(1);
    let mut counter = Counter::new(planned_renders(strategies.len(), ladder, repeat));
    let mut contestants = Vec::with_capacity(strategies.len());
    for (index, strategy) in strategies.iter().enumerate() {
        let (scene, settings) = setup.prepare(strategy)?;
        let mut c = Contestant {
            index,
            strategy,
            scene,
            settings,
            budgets: Vec::new(),
        };
        c.budgets = match ladder {
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
                calibrated_budgets(setup, &c, base, budgets, &mut counter, progress)?
            }
        };
        contestants.push(c);
    }
    let steps = contestants
        .iter()
        .map(|c| c.budgets.len())
        .max()
        .unwrap_or(0);
    let mut measurements: Vec<Measurement> = Vec::new();
    for step in 0..steps {
        let first = measurements.len();
        for run in 0..repeat {
            for c in &contestants {
                let Some(&budget) = c.budgets.get(step) else {
                    continue;
                };
                let what = format!(
                    "{} at {} spp × {} light samples (run {} of {repeat})",
                    c.strategy.name(),
                    budget.spp,
                    budget.light_samples,
                    run + 1,
                );
                counter.next(&what, progress);
                let output = setup.render(&c.scene, &c.settings_at(budget)?, progress)?;
                match measurements[first..]
                    .iter_mut()
                    .find(|m| m.strategy == c.index)
                {
                    Some(m) => m.times.push(output.stats.elapsed),
                    None => measurements.push(Measurement {
                        strategy: c.index,
                        budget,
                        times: vec![output.stats.elapsed],
                        stats: output.stats,
                        image: output.film.pixels().to_vec(),
                    }),
                }
            }
        }
    }
    measurements.sort_by_key(|m| m.strategy);
    Ok(measurements)
}

/// The sample budgets that render in about the given times with a strategy:
/// a render at 1 and at 4 spp fits `time = a + b·spp`, each budget gets
/// `spp = (T − a)/b` rounded (to a square for the grid pattern), at least 1, and
/// budgets that come out equal are rendered once.
fn calibrated_budgets(
    setup: &Setup,
    contestant: &Contestant,
    base: SampleBudget,
    times: &[Duration],
    counter: &mut Counter,
    progress: &(dyn Fn(Progress) + Sync),
) -> Result<Vec<SampleBudget>, BenchError> {
    let mut seconds = [0.0; 2];
    for (slot, spp) in [1u32, 4].into_iter().enumerate() {
        let settings = contestant.settings_at(SampleBudget { spp, ..base })?;
        let what = format!("{}: timing {spp} spp", contestant.strategy.name());
        counter.next(&what, progress);
        let output = setup.render(&contestant.scene, &settings, progress)?;
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
        let spp = if contestant.strategy.pixel == glint_integrator::SamplePattern::Grid {
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
        Ladder::Samples(b) => b.len() * repeat,
        Ladder::Time { budgets, .. } => 2 + budgets.len() * repeat,
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

    /// Announces the next render.
    pub(crate) fn next(&mut self, what: &str, progress: &(dyn Fn(Progress) + Sync)) {
        self.done += 1;
        self.total = self.total.max(self.done);
        progress(Progress::Render {
            number: self.done,
            planned: self.total,
            what,
        });
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
