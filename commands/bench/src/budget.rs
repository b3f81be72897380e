//! Budgets: how much work each render of the sweep may do, as sample counts or as
//! wall-clock time.

use std::time::Duration;

/// Sample counts of one render: camera samples per pixel, and per camera sample
/// the samples on each area light and the environment directions.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SampleBudget {
    pub spp: u32,
    pub light_samples: u32,
    pub environment_samples: u32,
}

impl SampleBudget {
    /// Light-sample paths per pixel, `spp · light_samples`: the sample count that
    /// error slopes and the "total samples" of the report refer to. (With the
    /// default of one light sample per camera sample it is the spp.)
    pub fn total_samples(&self) -> u64 {
        self.spp as u64 * self.light_samples as u64
    }
}

/// The ladder a sweep climbs for every strategy.
#[derive(Clone, Debug, PartialEq)]
pub enum Ladder {
    /// Fixed sample counts, in increasing order.
    Samples(Vec<SampleBudget>),
    /// Wall-clock budgets: each strategy gets the spp that renders in about that
    /// long on this machine (light and environment samples fixed).
    Time {
        budgets: Vec<Duration>,
        light_samples: u32,
        environment_samples: u32,
    },
}

/// Parses a comma-separated list of whole numbers, each at least `min`.
pub fn parse_counts(flag: &str, list: &str, min: u32) -> Result<Vec<u32>, String> {
    list.split(',')
        .map(|item| {
            let item = item.trim();
            match item.parse::<u32>() {
                Ok(n) if n >= min => Ok(n),
                _ => Err(format!(
                    "{flag}: expected whole numbers of at least {min} separated by commas, got \"{item}\""
                )),
            }
        })
        .collect()
}

/// Parses a list of durations such as `0.1s,300ms,1s,3s`.
pub fn parse_durations(list: &str) -> Result<Vec<Duration>, String> {
    list.split(',')
        .map(|item| {
            let item = item.trim();
            let (number, scale) = if let Some(ms) = item.strip_suffix("ms") {
                (ms, 1e-3)
            } else if let Some(s) = item.strip_suffix('s') {
                (s, 1.0)
            } else {
                (item, 1.0)
            };
            match number.trim().parse::<f64>() {
                Ok(x) if x.is_finite() && x > 0.0 && x * scale <= 86_400.0 => {
                    Ok(Duration::from_secs_f64(x * scale))
                }
                _ => Err(format!(
                    "--time: expected durations such as 0.1s, 300ms or 2 (seconds, at most a day), got \"{item}\""
                )),
            }
        })
        .collect()
}

/// The ladder of sample budgets from the three lists: a list of one value is
/// used at every step; lists of several values must be equally long and are
/// paired step by step (`--spp 1,4,16 --light-samples 1,4,16`).
pub fn sample_ladder(
    spp: &[u32],
    light_samples: &[u32],
    environment_samples: &[u32],
) -> Result<Vec<SampleBudget>, String> {
    let steps = [spp.len(), light_samples.len(), environment_samples.len()]
        .into_iter()
        .max()
        .unwrap_or(0);
    let lists = [
        ("--spp", spp),
        ("--light-samples", light_samples),
        ("--environment-samples", environment_samples),
    ];
    for (flag, list) in lists {
        if list.is_empty() || (list.len() != 1 && list.len() != steps) {
            return Err(format!(
                "{flag}: give one value or {steps} (as many as the longest list), got {}",
                list.len()
            ));
        }
    }
    let at = |list: &[u32], i: usize| if list.len() == 1 { list[0] } else { list[i] };
    let ladder: Vec<SampleBudget> = (0..steps)
        .map(|i| SampleBudget {
            spp: at(spp, i),
            light_samples: at(light_samples, i),
            environment_samples: at(environment_samples, i),
        })
        .collect();
    if ladder.windows(2).any(|w| {
        w[1].total_samples() * w[1].environment_samples.max(1) as u64
            <= w[0].total_samples() * w[0].environment_samples.max(1) as u64
    }) {
        return Err("the sample budgets must grow from step to step".into());
    }
    Ok(ladder)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_of_one_are_used_at_every_step() {
        let ladder = sample_ladder(&[1, 4, 16], &[1], &[2]).unwrap();
        assert_eq!(ladder.len(), 3);
        assert_eq!(
            ladder[2],
            SampleBudget {
                spp: 16,
                light_samples: 1,
                environment_samples: 2
            }
        );
        let paired = sample_ladder(&[1, 4], &[1, 4], &[1]).unwrap();
        assert_eq!(paired[1].total_samples(), 16);
    }

    #[test]
    fn unequal_or_shrinking_lists_are_refused() {
        assert!(sample_ladder(&[1, 4, 16], &[1, 4], &[1])
            .unwrap_err()
            .contains("--light-samples"));
        assert!(sample_ladder(&[4, 1], &[1], &[1])
            .unwrap_err()
            .contains("grow"));
    }

    #[test]
    fn counts_and_durations_parse_or_say_why_not() {
        assert_eq!(parse_counts("--spp", "1, 4,16", 1).unwrap(), [1, 4, 16]);
        assert!(parse_counts("--spp", "1,0", 1)
            .unwrap_err()
            .contains("\"0\""));
        assert!(parse_counts("--spp", "1,x", 1)
            .unwrap_err()
            .contains("--spp"));
        assert_eq!(parse_counts("--environment-samples", "0", 0).unwrap(), [0]);
        let d = parse_durations("0.1s,300ms,2").unwrap();
        assert_eq!(d[0], Duration::from_millis(100));
        assert_eq!(d[1], Duration::from_millis(300));
        assert_eq!(d[2], Duration::from_secs(2));
        assert!(parse_durations("1h").is_err());
        assert!(parse_durations("-1s").is_err());
        assert!(parse_durations("nans").is_err());
    }
}
