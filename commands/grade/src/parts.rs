//! A class graded in parts, on several machines (`glint farm … grade`):
//! part I of N grades submissions I, I + N, I + 2N, … of the class and
//! writes a part folder ([`PartFile`] as `part.json`, and its images); the
//! merge reads the parts back, checks that they are one class's and cover it
//! exactly once, and gives the rows and images a single run would have made,
//! from which the same report is written.
//!
//! Reference sets are numbered by where they are first used in the class
//! (`images/reference-G.png`); a part numbers its own, and names each by
//! its scene, resolution and settings, so that the merge can number them as
//! the single run does.

use crate::class::{ClassGrades, Entry};
use crate::report::ReportRow;
use crate::GradeError;
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The schema name of `part.json`.
pub const PART_SCHEMA: &str = "glint-grade-part/1";
/// A part folder's description.
pub const PART_FILE: &str = "part.json";

/// Part `index` of `count`: the submissions `index`, `index + count`, …
/// of the class, dealt out in turn so that every part has some of each
/// student's scenes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Part {
    pub index: usize,
    pub count: usize,
}

impl Part {
    /// Parses `I/N` (0 ≤ I < N).
    pub fn parse(text: &str) -> Result<Part, String> {
        let expected = || {
            format!(
                "expected I/N with 0 ≤ I < N (parts count from 0), got \"{}\"",
                crate::text::shorten(text)
            )
        };
        let (index, count) = text.split_once('/').ok_or_else(expected)?;
        let number = |s: &str| s.trim().parse::<usize>().map_err(|_| expected());
        let (index, count) = (number(index)?, number(count)?);
        if count == 0 || index >= count {
            return Err(expected());
        }
        Ok(Part { index, count })
    }

    /// Whether submission `i` of the class is this part's.
    pub fn has(&self, i: usize) -> bool {
        i % self.count == self.index
    }

    /// The class's index of the part's `k`-th submission.
    pub fn submission(&self, k: usize) -> usize {
        self.index + k * self.count
    }
}

impl std::fmt::Display for Part {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

/// What a part folder's `part.json` holds.
#[derive(Debug, Serialize, Deserialize)]
pub struct PartFile {
    pub schema: String,
    /// The class and how it is graded ([`class_fingerprint`]): the same in
    /// every part of one class.
    pub class: String,
    pub part: Part,
    /// The submissions of the whole class.
    pub submissions: usize,
    /// The part's rows, each with its index in the class; a row's
    /// `reference` numbers the part's own reference sets.
    pub rows: Vec<PartRow>,
    /// The part's reference sets, by what they are: scene, resolution and
    /// settings.
    pub references: Vec<String>,
}

#[derive(Debug, Serialize, Deserialize)]
pub struct PartRow {
    pub index: usize,
    pub row: ReportRow,
}

/// Names a class and how it is graded: the glint that grades, the options
/// (`options`: the test's, the stated settings, where scenes are found) and
/// every submission. Parts of one class agree on it.
pub fn class_fingerprint(entries: &[Entry], options: &str) -> String {
    let listed = entries.iter().fold(0xcbf2_9ce4_8422_2325_u64, |h, e| {
        let text = format!(
            "{}\u{0}{}\u{0}{}\u{0}{:?}\u{0}",
            e.student,
            e.scene,
            e.file.display(),
            e.stated
        );
        text.bytes()
            .fold(h, |h, b| (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3))
    });
    format!(
        "glint {} grade; {options}; {} submissions {listed:016x}",
        env!("CARGO_PKG_VERSION"),
        entries.len()
    )
}

/// The part file of `part` of a class (`submissions` in all) graded as
/// `grades`, whose rows are the part's submissions in order.
pub fn part_file(class: String, part: Part, submissions: usize, grades: &ClassGrades) -> PartFile {
    let rows = crate::report::rows(grades)
        .into_iter()
        .enumerate()
        .map(|(k, row)| PartRow {
            index: part.submission(k),
            row,
        })
        .collect();
    PartFile {
        schema: PART_SCHEMA.into(),
        class,
        part,
        submissions,
        rows,
        references: grades.groups.iter().map(|g| g.key()).collect(),
    }
}

/// Writes `part.json` into the part folder `dir` (its images are there already).
pub fn write_part(dir: &Path, file: &PartFile) -> Result<(), GradeError> {
    let text = serde_json::to_string_pretty(file).expect("JSON") + "\n";
    crate::output::write_text(&dir.join(PART_FILE), &text)
}

/// A class merged from its parts.
#[derive(Debug)]
pub struct Merged {
    /// Every submission's row in class order, reference sets numbered as a
    /// single run numbers them.
    pub rows: Vec<ReportRow>,
    /// The part folder holding each row's images.
    pub row_parts: Vec<PathBuf>,
    /// Each reference set's image, where a submission judged against it
    /// was graded: the part folder and its number there.
    pub references: Vec<Option<(PathBuf, usize)>>,
}

/// Reads the part folders `dirs` and merges them; refuses parts of other
/// classes, a part given twice, missing parts (naming them), and files
/// that are not parts.
pub fn merge(dirs: &[PathBuf]) -> Result<Merged, GradeError> {
    let input =
        |dir: &Path, message: String| GradeError::Input(format!("{}: {message}", dir.display()));
    let mut parts: Vec<(PathBuf, PartFile)> = Vec::with_capacity(dirs.len());
    for dir in dirs {
        let path = dir.join(PART_FILE);
        let text = glint_scene::read_text(&path, glint_scene::MAX_DOCUMENT_BYTES, "a part file")
            .map_err(|e| {
                input(
                    dir,
                    format!("not a part folder of a class graded in parts ({PART_FILE}: {e})"),
                )
            })?;
        let file: PartFile = serde_json::from_str(&text).map_err(|e| {
            input(
                dir,
                format!(
                    "{PART_FILE}: not a part file of glint grade's: {}",
                    crate::text::shorten(&e.to_string())
                ),
            )
        })?;
        if file.schema != PART_SCHEMA {
            return Err(input(
                dir,
                format!(
                    "{PART_FILE}: schema \"{}\", expected \"{PART_SCHEMA}\"",
                    crate::text::shorten(&file.schema)
                ),
            ));
        }
        if let Some((first, f)) = parts.first() {
            if f.class != file.class {
                return Err(input(dir, format!(
                    "a part of another class than {}, or of the class graded with other options: their {PART_FILE}'s \"class\" differ; grade every part with the same command",
                    first.display()
                )));
            }
            if f.part.count != file.part.count || f.submissions != file.submissions {
                return Err(input(
                    dir,
                    format!(
                        "part {} of {} submissions, and {} is part {} of {}: the parts of one class agree on both",
                        file.part,
                        file.submissions,
                        first.display(),
                        f.part,
                        f.submissions
                    ),
                ));
            }
        }
        if let Some((twice, _)) = parts.iter().find(|(_, f)| f.part == file.part) {
            return Err(input(
                dir,
                format!(
                    "part {} is given twice (also {})",
                    file.part,
                    twice.display()
                ),
            ));
        }
        check_rows(&file).map_err(|m| input(dir, m))?;
        parts.push((dir.clone(), file));
    }
    let Some((_, first)) = parts.first() else {
        return Err(GradeError::Input("--merge: no part folders given".into()));
    };
    let (count, submissions) = (first.part.count, first.submissions);
    let missing: Vec<String> = (0..count)
        .filter(|i| !parts.iter().any(|(_, f)| f.part.index == *i))
        .map(|i| format!("{i}/{count}"))
        .collect();
    if !missing.is_empty() {
        return Err(GradeError::Input(format!(
            "missing parts {}: grade them (glint grade --part I/N) and merge again",
            missing.join(", ")
        )));
    }
    let mut slots: Vec<Option<(ReportRow, usize)>> = vec![None; submissions];
    for (p, (_, file)) in parts.iter().enumerate() {
        for r in &file.rows {
            slots[r.index] = Some((r.row.clone(), p));
        }
    }
    let mut merged = Merged {
        rows: Vec::with_capacity(submissions),
        row_parts: Vec::with_capacity(submissions),
        references: Vec::new(),
    };
    // Reference sets numbered by first use, as a single run numbers them;
    // each one's image from the part of its first graded submission.
    let mut keys: Vec<&str> = Vec::new();
    let mut images: Vec<Option<(PathBuf, usize)>> = Vec::new();
    for slot in slots {
        let (mut row, p) = slot.expect("every part's rows are there, each its own");
        let (dir, file) = &parts[p];
        if let Some(local) = row.reference {
            let key = file.references[local].as_str();
            let global = keys.iter().position(|k| *k == key).unwrap_or_else(|| {
                keys.push(key);
                images.push(None);
                keys.len() - 1
            });
            if row.graded() && images[global].is_none() {
                images[global] = Some((dir.clone(), local));
            }
            row.reference = Some(global);
        }
        merged.rows.push(row);
        merged.row_parts.push(dir.clone());
    }
    merged.references = images;
    Ok(merged)
}

/// A part's rows are the part's submissions of the class, each once, and
/// name reference sets it has.
fn check_rows(file: &PartFile) -> Result<(), String> {
    let Part { index, count } = file.part;
    if count == 0 || index >= count {
        return Err(format!("{PART_FILE}: part {index}/{count} is no part"));
    }
    let expected = file.submissions.saturating_sub(index).div_ceil(count);
    let mine = |k: usize, r: &PartRow| r.index == index + k * count;
    if file.rows.len() != expected || !file.rows.iter().enumerate().all(|(k, r)| mine(k, r)) {
        return Err(format!(
            "{PART_FILE}: its rows are not part {}'s submissions of {}",
            file.part, file.submissions
        ));
    }
    let references = file.references.len();
    match file
        .rows
        .iter()
        .find(|r| r.row.reference.is_some_and(|g| g >= references))
    {
        Some(r) => Err(format!(
            "{PART_FILE}: submission {} names reference set {} of {references}",
            r.index,
            r.row.reference.unwrap_or(0)
        )),
        None => Ok(()),
    }
}

/// Copies the merged class's images from its parts into the report folder
/// `dir`, reference sets renamed to their class numbers.
pub fn copy_images(merged: &Merged, dir: &Path) -> Result<(), GradeError> {
    let images = dir.join("images");
    std::fs::create_dir_all(&images)
        .map_err(|e| GradeError::Internal(format!("{}: {e}", images.display())))?;
    let copy = |from: PathBuf, to: PathBuf| {
        std::fs::copy(&from, &to).map(drop).map_err(|e| {
            GradeError::Input(format!(
                "{}: cannot copy the part's image: {e}",
                from.display()
            ))
        })
    };
    for (i, (row, part)) in merged.rows.iter().zip(&merged.row_parts).enumerate() {
        if row.reference.is_none() || !row.graded() {
            continue;
        }
        for name in crate::html::submission_images(i) {
            copy(part.join("images").join(&name), images.join(&name))?;
        }
        if row.best_fit.is_some() {
            for name in crate::html::fit_images(i) {
                copy(part.join("images").join(&name), images.join(&name))?;
            }
        }
    }
    let references = merged.references.iter().enumerate();
    for (g, (part, local)) in references.filter_map(|(g, r)| Some((g, r.as_ref()?))) {
        for (from, to) in crate::html::reference_images(*local)
            .into_iter()
            .zip(crate::html::reference_images(g))
        {
            copy(part.join("images").join(from), images.join(to))?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parts_deal_the_submissions_out_in_turn() {
        let part = Part::parse("1/3").unwrap();
        let mine: Vec<usize> = (0..8).filter(|&i| part.has(i)).collect();
        assert_eq!(mine, [1, 4, 7]);
        assert_eq!((0..3).map(|k| part.submission(k)).collect::<Vec<_>>(), mine);
        for bad in ["3/3", "1/0", "1", "a/b", "-1/3"] {
            assert!(Part::parse(bad).is_err(), "{bad}");
        }
    }

    /// A part file edited by hand is refused, not followed: no division by
    /// a zero count, no room made for the submissions it claims.
    #[test]
    fn malformed_part_files_are_refused() {
        let file = |index, count, submissions, rows: &[usize]| PartFile {
            schema: PART_SCHEMA.into(),
            class: String::new(),
            part: Part { index, count },
            submissions,
            rows: rows
                .iter()
                .map(|&index| PartRow { index, row: row() })
                .collect(),
            references: Vec::new(),
        };
        assert!(check_rows(&file(0, 0, 4, &[])).is_err());
        assert!(check_rows(&file(2, 2, 4, &[])).is_err());
        assert!(check_rows(&file(0, 1, usize::MAX, &[0])).is_err());
        assert!(check_rows(&file(1, 2, 5, &[1, 4])).is_err());
        assert!(check_rows(&file(1, 2, 5, &[1, 3])).is_ok());
    }

    fn row() -> ReportRow {
        ReportRow {
            student: "ada".into(),
            scene: "set1".into(),
            file: "ada/set1.png".into(),
            format: String::new(),
            verdict: "error".into(),
            summary: String::new(),
            numbers: Default::default(),
            json: serde_json::Value::Null,
            sort_key: String::new(),
            reference: None,
            views: Vec::new(),
            best_fit: None,
        }
    }
}
