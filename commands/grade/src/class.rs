//! A class at once: submissions listed by a folder (`DIR/STUDENT/SCENE.png`)
//! or a CSV manifest, graded in parallel, each scene's references rendered
//! (or read from the cache) once per resolution and settings.

use crate::course::Scenes;
use crate::hypothesis::{ReferencePlan, StatedSettings};
use crate::jpeg::JpegEncoding;
use crate::reference::{references, with_jpeg, Cache, GradeScene, References};
use crate::submission::Submission;
use crate::test::TestOptions;
use crate::text::shorten;
use crate::{grade_image, mistakes, GradeError, ImageGrade};
use glam::UVec2;
use glint_integrator::SamplePattern;
use rayon::prelude::*;
use serde::Serialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// The image extensions a class folder's submissions may have (a file's
/// content, not its name, says what it is).
pub const IMAGE_EXTENSIONS: [&str; 14] = [
    "png", "ppm", "pgm", "pnm", "jpg", "jpeg", "bmp", "tga", "hdr", "pic", "exr", "pfm", "pam",
    "pbm",
];

/// The columns a manifest may have; the first three are required.
pub const MANIFEST_COLUMNS: [&str; 8] = [
    "student",
    "scene",
    "file",
    "spp",
    "sampler",
    "light_samples",
    "light_sampler",
    "note",
];

/// One submission of a class.
#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    pub student: String,
    /// The scene as the class names it (a name in the scenes folder, or a path).
    pub scene: String,
    pub file: PathBuf,
    /// The settings it is judged under (the command's, or its manifest row's).
    pub stated: StatedSettings,
}

/// One scene's submissions, named by their files (`glint grade SCENE
/// IMAGE…`): each student the file's stem, all judged under `stated`.
pub fn entries_of_scene(scene: &Path, files: &[PathBuf], stated: &StatedSettings) -> Vec<Entry> {
    let student = |file: &Path| {
        file.file_stem()
            .map_or(String::new(), |s| s.to_string_lossy().into_owned())
    };
    files
        .iter()
        .map(|file| Entry {
            student: student(file),
            scene: scene.display().to_string(),
            file: file.clone(),
            stated: *stated,
        })
        .collect()
}

/// The submissions of a folder: every image `DIR/STUDENT/SCENE.EXT`, the
/// scene named by the file's stem, students and files in name order.
pub fn entries_from_folder(dir: &Path, stated: &StatedSettings) -> Result<Vec<Entry>, GradeError> {
    let read = |d: &Path| {
        std::fs::read_dir(d)
            .and_then(|entries| {
                entries
                    .map(|e| e.map(|e| e.path()))
                    .collect::<Result<Vec<_>, _>>()
            })
            .map_err(|e| GradeError::Input(format!("{}: cannot read the folder: {e}", d.display())))
    };
    let mut students = read(dir)?;
    students.retain(|p| p.is_dir());
    students.sort();
    let mut entries = Vec::new();
    for student_dir in students {
        let student = file_name(&student_dir);
        let mut files = read(&student_dir)?;
        files.retain(|p| p.is_file() && is_image(p));
        files.sort();
        for file in files {
            let scene = file
                .file_stem()
                .map_or(String::new(), |s| s.to_string_lossy().into_owned());
            entries.push(Entry {
                student: student.clone(),
                scene,
                file,
                stated: *stated,
            });
        }
    }
    if entries.is_empty() {
        return Err(GradeError::Input(format!(
            "{}: no submissions found; expected images at {}/STUDENT/SCENE.png (or .jpg, .ppm, .bmp, .tga, .hdr, .exr, .pfm)",
            dir.display(),
            dir.display()
        )));
    }
    Ok(entries)
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .map_or(String::new(), |n| n.to_string_lossy().into_owned())
}

fn is_image(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| IMAGE_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
}

/// The submissions a CSV manifest lists: a header row naming its columns
/// ([`MANIFEST_COLUMNS`]; `student`, `scene` and `file` required), then one
/// row per submission. Files are relative to the manifest; empty settings
/// cells take `stated`'s values.
pub fn entries_from_manifest(
    path: &Path,
    stated: &StatedSettings,
) -> Result<Vec<Entry>, GradeError> {
    let input = |message: String| GradeError::Input(format!("{}: {message}", path.display()));
    let text = glint_scene::read_text(path, glint_scene::MAX_DOCUMENT_BYTES, "a manifest")
        .map_err(|e| input(format!("cannot read the manifest: {e}")))?;
    let mut reader = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let header = reader
        .headers()
        .map_err(|e| input(csv_problem(&e)))?
        .clone();
    let columns = Columns::new(&header).map_err(|e| input(format!("line 1: {e}")))?;
    let base = path.parent().unwrap_or(Path::new(""));
    let mut entries = Vec::new();
    for record in reader.records() {
        let record = record.map_err(|e| input(csv_problem(&e)))?;
        let line = record.position().map_or(0, |p| p.line());
        let at = |message: String| input(format!("line {line}: {message}"));
        entries.push(columns.entry(&record, base, stated).map_err(at)?);
    }
    if entries.is_empty() {
        return Err(input("the manifest lists no submissions".into()));
    }
    Ok(entries)
}

fn csv_problem(e: &csv::Error) -> String {
    match e.position() {
        Some(p) => format!(
            "line {}: not valid CSV: {}",
            p.line(),
            shorten(&e.to_string())
        ),
        None => format!("not valid CSV: {}", shorten(&e.to_string())),
    }
}

/// Where each known column is in a manifest's rows.
struct Columns {
    index: BTreeMap<&'static str, usize>,
}

impl Columns {
    fn new(header: &csv::StringRecord) -> Result<Columns, String> {
        let mut index = BTreeMap::new();
        for (i, name) in header.iter().enumerate() {
            let known = MANIFEST_COLUMNS
                .iter()
                .find(|c| c.eq_ignore_ascii_case(name))
                .ok_or_else(|| {
                    format!(
                        "unknown column \"{}\"; expected {}",
                        shorten(name),
                        MANIFEST_COLUMNS.join(", ")
                    )
                })?;
            if index.insert(*known, i).is_some() {
                return Err(format!("the column \"{known}\" appears twice"));
            }
        }
        if let Some(missing) = MANIFEST_COLUMNS[..3]
            .iter()
            .find(|c| !index.contains_key(*c))
        {
            return Err(format!(
                "no \"{missing}\" column; a manifest needs student, scene and file"
            ));
        }
        Ok(Columns { index })
    }

    fn cell<'r>(&self, record: &'r csv::StringRecord, column: &str) -> Option<&'r str> {
        self.index
            .get(column)
            .and_then(|&i| record.get(i))
            .filter(|cell| !cell.is_empty())
    }

    fn entry(
        &self,
        record: &csv::StringRecord,
        base: &Path,
        defaults: &StatedSettings,
    ) -> Result<Entry, String> {
        let required = |column: &str| {
            self.cell(record, column)
                .map(str::to_owned)
                .ok_or_else(|| format!("the {column} cell is empty"))
        };
        let count = |column: &str| -> Result<Option<u32>, String> {
            self.cell(record, column)
                .map(|cell| {
                    cell.parse::<u32>().ok().filter(|&n| n >= 1).ok_or_else(|| {
                        format!(
                            "{column} is \"{}\"; expected a whole number, 1 or more",
                            shorten(cell)
                        )
                    })
                })
                .transpose()
        };
        let pattern = |column: &str| -> Result<Option<SamplePattern>, String> {
            self.cell(record, column)
                .map(|cell| {
                    SamplePattern::from_name(cell).ok_or_else(|| {
                        format!(
                            "{column} is \"{}\"; expected one of {}",
                            shorten(cell),
                            SamplePattern::NAMES.join(", ")
                        )
                    })
                })
                .transpose()
        };
        let stated = StatedSettings {
            spp: count("spp")?,
            pixel_pattern: pattern("sampler")?,
            light_samples: count("light_samples")?,
            light_pattern: pattern("light_sampler")?,
        };
        Ok(Entry {
            student: required("student")?,
            scene: required("scene")?,
            file: base.join(required("file")?),
            stated: stated.or(defaults),
        })
    }
}

/// How a class is graded.
#[derive(Clone, Debug, Default)]
pub struct ClassOptions {
    pub test: TestOptions,
    pub cache: Cache,
    /// Whether a failing submission is tested against the classic
    /// mistakes ([`crate::mistakes`]).
    pub mistakes: bool,
}

/// What becomes of one submission.
#[derive(Clone, Debug, Serialize)]
#[serde(tag = "status", rename_all = "snake_case")]
pub enum Outcome {
    /// Graded: passed, failed, or found unreadable for grading.
    Graded(Box<ImageGrade>),
    /// Not graded: the file could not be read, or its scene not found.
    Unreadable { message: String },
}

/// One row of a class's results.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    pub student: String,
    pub scene: String,
    pub file: String,
    #[serde(flatten)]
    pub outcome: Outcome,
    /// Which of the class's reference sets it was judged against.
    #[serde(skip)]
    pub group: Option<usize>,
}

impl Row {
    pub fn passed(&self) -> bool {
        matches!(&self.outcome, Outcome::Graded(g) if g.passed)
    }
}

/// A graded class: a row per submission, and the references they used.
pub struct ClassGrades {
    pub rows: Vec<Row>,
    pub groups: Vec<Group>,
}

impl ClassGrades {
    pub fn all_passed(&self) -> bool {
        self.rows.iter().all(Row::passed)
    }
}

/// Submissions judged against the same references: one scene, resolution
/// and set of stated settings.
pub struct Group {
    pub scene: Arc<GradeScene>,
    pub stated: StatedSettings,
    pub references: References,
}

impl Group {
    /// What the reference set is, in words: its scene, resolution and
    /// settings.
    pub fn key(&self) -> String {
        let size = self.references.resolution;
        format!(
            "{} at {}x{}, {:?}",
            self.scene.path.display(),
            size.x,
            size.y,
            self.stated
        )
    }
}

/// What a class run reports as it goes.
pub trait Progress: Sync {
    /// A reference is being rendered (a line of text).
    fn rendering(&self, what: &str);
    /// `done` of `total` submissions are graded.
    fn graded(&self, done: usize, total: usize);
}

/// Called with each graded submission, its image and references (to write
/// its heat map, say), from worker threads.
pub type OnGraded<'a> =
    dyn Fn(usize, &Row, &Submission, &Group) -> Result<(), GradeError> + Sync + 'a;

/// Called with each failing submission a mistake fits (by its row index),
/// with Glint's render of the best fit as the submission would store it
/// ([`mistakes::fit_image`]), from worker threads.
pub type OnDiagnosed<'a> =
    dyn Fn(usize, &[glam::Vec3], glam::UVec2) -> Result<(), GradeError> + Sync + 'a;

/// What is done with each submission's images as the class is graded.
pub struct Hooks<'a> {
    pub on_graded: &'a OnGraded<'a>,
    pub on_diagnosed: &'a OnDiagnosed<'a>,
}

/// Grades every entry; scenes are looked up in `scenes` (relative to `base`),
/// whose presets fill the settings an entry leaves unknown.
pub fn grade_class(
    entries: &[Entry],
    scenes: &Scenes,
    base: &Path,
    options: &ClassOptions,
    progress: &dyn Progress,
    hooks: Hooks,
) -> Result<ClassGrades, GradeError> {
    let on_graded = hooks.on_graded;
    let Prepared {
        entries,
        probes,
        groups,
        row_groups,
    } = prepare(entries, scenes, base, options, progress)?;
    let done = AtomicUsize::new(0);
    let rows: Vec<Row> = entries
        .par_iter()
        .zip(probes.par_iter())
        .zip(row_groups.par_iter())
        .enumerate()
        .map(|(i, (((entry, _), probe), group))| {
            let row = grade_row(i, entry, probe, *group, &groups, options, on_graded);
            progress.graded(done.fetch_add(1, Ordering::Relaxed) + 1, entries.len());
            row
        })
        .collect::<Result<_, GradeError>>()?;
    let mut rows = rows;
    if options.mistakes {
        diagnose_failures(&mut rows, &groups, options, progress, hooks.on_diagnosed)?;
    }
    Ok(ClassGrades { rows, groups })
}

/// Tests each failing row against the classic mistakes, rendered once per
/// reference set that has a failing row.
fn diagnose_failures(
    rows: &mut [Row],
    groups: &[Group],
    options: &ClassOptions,
    progress: &dyn Progress,
    on_diagnosed: &OnDiagnosed,
) -> Result<(), GradeError> {
    for (g, group) in groups.iter().enumerate() {
        let failing: Vec<usize> = (0..rows.len())
            .filter(|&i| rows[i].group == Some(g) && failed(&rows[i]))
            .collect();
        if failing.is_empty() {
            continue;
        }
        let rendering = |what: &str| progress.rendering(what);
        let mut mutants = mistakes::render_mutants(
            &group.scene,
            &group.references,
            &group.stated,
            &options.cache,
            &rendering,
        )?;
        // A failing submission, if it can be diagnosed: read where needed,
        // not kept (a class's failing images may not fit in memory at once).
        let load = |i: usize| {
            Submission::load(Path::new(&rows[i].file))
                .ok()
                .filter(|s| s.resolution() == group.references.resolution)
        };
        let jpegs: Vec<JpegEncoding> = (failing.par_iter())
            .filter_map(|&i| load(i)?.jpeg?.ok())
            .collect();
        let mut encodings: Vec<&JpegEncoding> = Vec::new();
        for encoding in &jpegs {
            if !encodings.contains(&encoding) {
                mutants.through_jpeg(encoding, &options.cache, &rendering)?;
                encodings.push(encoding);
            }
        }
        let against = mistakes::Against {
            scene: &group.scene,
            references: &group.references,
            stated: &group.stated,
            mutants: &mutants,
            cache: &options.cache,
            progress: &rendering,
        };
        let found: Vec<Vec<mistakes::LikelyMistake>> = (failing.par_iter())
            .map(|&i| match load(i) {
                Some(s) => {
                    let found = mistakes::diagnose(&against, &s, &options.test)?;
                    if let Some(best) = found.first().filter(|m| m.consistent) {
                        if let Some(image) = mistakes::fit_image(&against, &s, &best.id)? {
                            on_diagnosed(i, &image, s.resolution())?;
                        }
                    }
                    Ok(found)
                }
                None => Ok(Vec::new()),
            })
            .collect::<Result<_, GradeError>>()?;
        for (i, found) in failing.into_iter().zip(found) {
            if let Outcome::Graded(grade) = &mut rows[i].outcome {
                grade.likely_mistakes = found;
            }
        }
    }
    Ok(())
}

/// Whether `row` was graded and failed.
fn failed(row: &Row) -> bool {
    matches!(&row.outcome, Outcome::Graded(g) if !g.passed && g.unreadable.is_none())
}

/// Renders the references `entries` need, and with `options.mistakes` their
/// mistakes, into the cache (or finds them there), and grades nothing: the first step of a class graded in parts,
/// whose parts then read them from the cache. Only the reference sets
/// `wanted` takes (by their index in order of first use: a part's are I, I +
/// N, …). Returns how many sets were rendered or found, and how many the
/// class has.
pub fn render_references(
    entries: &[Entry],
    scenes: &Scenes,
    base: &Path,
    options: &ClassOptions,
    progress: &dyn Progress,
    wanted: &dyn Fn(usize) -> bool,
) -> Result<(usize, usize), GradeError> {
    let (entries, loaded, probes) = probe(entries, scenes, base)?;
    let (keys, row_groups) = reference_keys(&entries, &probes);
    let mut groups = Vec::new();
    let mut mine = vec![None; keys.len()];
    for (i, key) in keys.iter().enumerate() {
        if wanted(i) {
            mine[i] = Some(groups.len());
            groups.push(reference_group(key, &loaded, options, progress)?);
        }
    }
    let row_groups: Vec<Option<usize>> =
        row_groups.iter().map(|g| g.and_then(|g| mine[g])).collect();
    through_jpeg(&mut groups, &probes, &row_groups, options, progress)?;
    // Which submissions fail is not known yet: every set's mistakes are
    // rendered, so that the parts find them all in the cache.
    if options.mistakes {
        let rendering = |what: &str| progress.rendering(what);
        for group in &groups {
            let (scene, refs) = (&group.scene, &group.references);
            mistakes::render_mutants(scene, refs, &group.stated, &options.cache, &rendering)?;
        }
    }
    Ok((groups.len(), keys.len()))
}

/// The entries with their settings completed, what each submission needs,
/// and the references, before any is graded.
struct Prepared {
    entries: Vec<Located>,
    probes: Vec<Probe>,
    groups: Vec<Group>,
    row_groups: Vec<Option<usize>>,
}

fn prepare(
    entries: &[Entry],
    scenes: &Scenes,
    base: &Path,
    options: &ClassOptions,
    progress: &dyn Progress,
) -> Result<Prepared, GradeError> {
    let (entries, loaded, probes) = probe(entries, scenes, base)?;
    let (keys, row_groups) = reference_keys(&entries, &probes);
    let mut groups: Vec<Group> = keys
        .iter()
        .map(|key| reference_group(key, &loaded, options, progress))
        .collect::<Result<_, _>>()?;
    through_jpeg(&mut groups, &probes, &row_groups, options, progress)?;
    Ok(Prepared {
        entries,
        probes,
        groups,
        row_groups,
    })
}

/// The entries with their settings completed, their scenes loaded, and
/// each submission's scene file and resolution, read from the file (and
/// dropped: grading reads it again).
fn probe(
    entries: &[Entry],
    scenes: &Scenes,
    base: &Path,
) -> Result<(Vec<Located>, Loaded, Vec<Probe>), GradeError> {
    let entries = with_presets(entries, scenes, base)?;
    let loaded = load_scenes(&entries, scenes);
    let probes: Vec<Probe> = entries
        .par_iter()
        .map(|(entry, found)| {
            let path = found.clone()?;
            loaded[&path].as_ref().map_err(Clone::clone)?;
            let submission = Submission::load(&entry.file)?;
            let resolution = submission.resolution();
            // Too lossy a JPEG is not graded: its encoding needs no references.
            let jpeg = submission
                .jpeg
                .and_then(Result::ok)
                .filter(|e| e.too_lossy().is_none());
            Ok((path, resolution, jpeg))
        })
        .collect();
    Ok((entries, loaded, probes))
}

/// A submission's scene file, resolution and JPEG encoding (if it is a JPEG
/// Glint can encode its renders as), or why it cannot be graded.
type Probe = Result<(PathBuf, UVec2, Option<JpegEncoding>), String>;

/// The scenes, each loaded once, by file; one that is missing or does not
/// load fails only its rows.
type Loaded = BTreeMap<PathBuf, Result<Arc<GradeScene>, String>>;

fn load_scenes(entries: &[Located], scenes: &Scenes) -> Loaded {
    let mut loaded = Loaded::new();
    if let Scenes::Loaded(scene) = scenes {
        loaded.insert(scene.path.clone(), Ok(scene.clone()));
    }
    for (_, found) in entries {
        let Ok(path) = found else { continue };
        loaded.entry(path.clone()).or_insert_with(|| {
            if path.is_file() {
                GradeScene::load(path)
                    .map(Arc::new)
                    .map_err(|e| e.to_string())
            } else {
                Err(format!("no scene file {}", path.display()))
            }
        });
    }
    loaded
}

/// A reference set: the scene file, the resolution and the stated settings.
type ReferenceKey = (PathBuf, UVec2, StatedSettings);

/// The reference sets readable submissions are judged against, in order of
/// first use (once per scene, resolution and stated settings), and each
/// row's.
fn reference_keys(
    entries: &[Located],
    probes: &[Probe],
) -> (Vec<ReferenceKey>, Vec<Option<usize>>) {
    let mut keys: Vec<ReferenceKey> = Vec::new();
    let row_groups = entries
        .iter()
        .zip(probes)
        .map(|((entry, _), probe)| {
            let (path, resolution, _) = probe.as_ref().ok()?;
            let key = (path.clone(), *resolution, entry.stated);
            Some(keys.iter().position(|k| *k == key).unwrap_or_else(|| {
                keys.push(key);
                keys.len() - 1
            }))
        })
        .collect();
    (keys, row_groups)
}

/// Passes the references of each group through the JPEG encodings of the
/// submissions judged against them (each row's group in `row_groups`).
fn through_jpeg(
    groups: &mut [Group],
    probes: &[Probe],
    row_groups: &[Option<usize>],
    options: &ClassOptions,
    progress: &dyn Progress,
) -> Result<(), GradeError> {
    for (probe, group) in probes.iter().zip(row_groups) {
        let (Ok((_, _, Some(encoding))), Some(g)) = (probe, group) else {
            continue;
        };
        let group = &mut groups[*g];
        let rendering = |what: &str| progress.rendering(what);
        let scene = Arc::clone(&group.scene);
        with_jpeg(
            &mut group.references,
            &scene,
            encoding,
            &options.cache,
            &rendering,
        )?;
    }
    Ok(())
}

/// The references of `key`, rendered or read from the cache.
fn reference_group(
    (path, resolution, stated): &ReferenceKey,
    loaded: &Loaded,
    options: &ClassOptions,
    progress: &dyn Progress,
) -> Result<Group, GradeError> {
    let scene = loaded[path].as_ref().expect("probed").clone();
    let plan = ReferencePlan::new(stated, scene.settings());
    let rendering = |what: &str| progress.rendering(what);
    let references = references(&scene, *resolution, &plan, &options.cache, &rendering)?;
    Ok(Group {
        scene,
        stated: *stated,
        references,
    })
}

/// What a report calls a scene: its name, or a scene file's stem.
fn display_name(scene: &str) -> String {
    match scene.strip_suffix(".toml") {
        Some(path) => Path::new(path)
            .file_name()
            .map_or(scene.to_owned(), |n| n.to_string_lossy().into_owned()),
        None => scene.to_owned(),
    }
}

/// An entry, and its scene file or why it has none.
type Located = (Entry, Result<PathBuf, String>);

/// Each entry with its settings completed by its scene's preset (checked),
/// and its scene file or why there is none.
fn with_presets(
    entries: &[Entry],
    scenes: &Scenes,
    base: &Path,
) -> Result<Vec<Located>, GradeError> {
    entries
        .iter()
        .map(|entry| {
            let (found, preset) = match scenes.resolve(&entry.scene, base) {
                Ok((path, preset)) => (Ok(path), preset),
                Err(message) => (Err(message), StatedSettings::default()),
            };
            let stated = entry.stated.or(&preset);
            stated.validate().map_err(|e| {
                GradeError::Input(format!(
                    "{} ({}, {}): the settings: {e}",
                    entry.file.display(),
                    shorten(&entry.student),
                    shorten(&entry.scene)
                ))
            })?;
            Ok((
                Entry {
                    stated,
                    ..entry.clone()
                },
                found,
            ))
        })
        .collect()
}

fn grade_row(
    index: usize,
    entry: &Entry,
    probe: &Probe,
    group: Option<usize>,
    groups: &[Group],
    options: &ClassOptions,
    on_graded: &OnGraded,
) -> Result<Row, GradeError> {
    let mut row = Row {
        student: entry.student.clone(),
        scene: display_name(&entry.scene),
        file: entry.file.display().to_string(),
        outcome: Outcome::Unreadable {
            message: String::new(),
        },
        group,
    };
    let (Ok(_), Some(g)) = (probe, group) else {
        let message = probe.as_ref().err().cloned().unwrap_or_default();
        row.outcome = Outcome::Unreadable { message };
        return Ok(row);
    };
    let group = &groups[g];
    let submission = match Submission::load(&entry.file) {
        Ok(s) if s.resolution() == group.references.resolution => s,
        Ok(_) => {
            row.outcome = Outcome::Unreadable {
                message: "the file changed while it was being graded".into(),
            };
            return Ok(row);
        }
        Err(message) => {
            row.outcome = Outcome::Unreadable { message };
            return Ok(row);
        }
    };
    let grade = grade_image(
        &group.scene,
        &group.references,
        &submission,
        &entry.stated,
        &options.test,
    );
    row.outcome = Outcome::Graded(Box::new(grade));
    on_graded(index, &row, &submission, group)?;
    Ok(row)
}
