//! `glint stress`: the numerical stress table of glint-stress (generated
//! configurations at scales from 1e-4 to 1e6, far from the origin, counting
//! shadow acne, light leaks, self-hits, off-surface points and non-finite
//! values, and the shipped scenes scaled and moved, judged pixel by pixel), with
//! an exit status that fails when any count is not zero.

use crate::Failure;
use clap::Args;
use glint_stress::{run, table, total, Row, Settings};

#[derive(Args)]
#[command(
    after_help = "Builds every configuration (floors under lights, and seen, down to 0.01° above the \
                  horizon, planes seen edge-on, a lone sphere, a tiny sphere on a huge one, \
                  closed boxes of walls, an AaBox, a box mesh and an icosahedron seen from \
                  inside and outside) at scales 1e-4 to 1e6, at the origin and up to 1e6 \
                  away, traces rays at a grid of points over each (edges, corners and \
                  shared vertices included unless --no-joints) as the renderer traces \
                  them, and prints a Markdown table of the counts that must be zero. \
                  The shipped scenes cornell-set1, bunny-cornell and bunny are scaled and \
                  moved whole, judged pixel by pixel against themselves at scale 1, and \
                  rendered (the last column: pixels changed by more than 1e-3, reported, \
                  not required to be zero). docs/testing.md describes each \
                  configuration.\n\n\
                  Exit status: 0 when every count is zero, 1 when any is not, 2 for bad \
                  flags."
)]
pub(crate) struct StressArgs {
    /// Rays per side of the grid aimed at each configuration (2 to 256)
    #[arg(long, value_name = "N", default_value_t = 16, value_parser = clap::value_parser!(u32).range(2..=256))]
    grid: u32,

    /// Aim the grid at the centres of its cells only, not exactly at edges,
    /// corners and shared vertices
    #[arg(long)]
    no_joints: bool,
}

pub(crate) fn stress(args: &StressArgs) -> Result<(), Failure> {
    let rows = run(Settings {
        grid: args.grid,
        joints: !args.no_joints,
    });
    crate::output::say(&table(&rows));
    let line = verdict(&rows)?;
    crate::output::say(&format!("{line}\n"));
    Ok(())
}

/// The summary line when every count is zero, else the failure naming how
/// many configurations counted something.
fn verdict(rows: &[Row]) -> Result<String, Failure> {
    let sum = total(rows);
    let dirty = rows.iter().filter(|r| !r.counts.clean()).count();
    if dirty == 0 {
        return Ok(format!(
            "stress: {} configurations, {} rays: every count is zero",
            rows.len(),
            sum.rays
        ));
    }
    Err(Failure::Other(format!(
        "stress: {dirty} of {} configurations counted what must be zero \
         ({} acne, {} leaks, {} self-hits, {} off-surface, {} non-finite, of {} rays)",
        rows.len(),
        sum.acne,
        sum.leaks,
        sum.self_hits,
        sum.off_surface,
        sum.non_finite,
        sum.rays
    )))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glint_stress::Counts;

    fn row(counts: Counts) -> Row {
        Row {
            configuration: "floor".into(),
            scale: 1.0,
            offset: 0.0,
            counts,
        }
    }

    #[test]
    fn any_nonzero_count_fails_and_zero_counts_pass() {
        let clean = row(Counts {
            rays: 10,
            ..Counts::default()
        });
        assert!(verdict(&[clean.clone(), clean.clone()]).is_ok());
        let leaky = row(Counts {
            rays: 10,
            leaks: 1,
            ..Counts::default()
        });
        match verdict(&[clean, leaky]) {
            Err(Failure::Other(m)) => assert!(m.contains("1 of 2 configurations"), "{m}"),
            _ => panic!("a leak must fail"),
        }
    }
}
