//! A class graded in one call to `glint grade --format json`'s document and
//! each graded submission's `--heatmap` picture: what the Python package and
//! `glint view` hand back, made as the command makes them.

use crate::class::{self, ClassOptions, Entry, Outcome, Progress};
use crate::course::Scenes;
use crate::GradeError;
use glam::UVec2;
use std::path::Path;
use std::sync::Mutex;

/// A graded class: the document and, per entry, its heat map where graded.
pub struct Graded {
    /// `glint grade --format json`'s document.
    pub document: serde_json::Value,
    /// Each entry's heat map (RGB8, rows from the top), `None` where it was
    /// not graded.
    pub heatmaps: Vec<Option<Heatmap>>,
}

/// [`crate::heatmap::heatmap`]'s picture of one submission.
#[derive(Clone, Debug)]
pub struct Heatmap {
    pub resolution: UVec2,
    pub rgb: Vec<u8>,
}

/// Grades `entries` as [`class::grade_class`] does, keeping each graded
/// submission's heat map.
pub fn grade_with_heatmaps(
    entries: &[Entry],
    (scenes, base): (&Scenes, &Path),
    options: &ClassOptions,
    progress: &dyn Progress,
) -> Result<Graded, GradeError> {
    let heatmaps = Mutex::new(vec![None; entries.len()]);
    let keep = |i: usize, row: &class::Row, s: &crate::Submission, g: &class::Group| {
        if let Outcome::Graded(grade) = &row.outcome {
            let rgb = crate::heatmap::heatmap(grade, &s.film, &g.references.objects);
            let resolution = s.film.resolution();
            heatmaps.lock().expect("no panic holds it")[i] = Some(Heatmap { resolution, rgb });
        }
        Ok(())
    };
    let hooks = class::Hooks {
        on_graded: &keep,
        on_diagnosed: &|_, _, _| Ok(()),
    };
    let grades = class::grade_class(entries, scenes, base, options, progress, hooks)?;
    let rows = crate::report::rows(&grades);
    Ok(Graded {
        document: crate::report::json(&rows),
        heatmaps: heatmaps.into_inner().expect("no panic holds it"),
    })
}
