//! `glint grade`: whether submitted images are unbiased renders of their
//! scenes (one scene's images, or a class by folder or manifest), and the
//! stages of a student's ray tracer against test vectors. The work is in
//! glint-grade; this file reads the flags and writes what it returns.

use crate::output::check_heatmap_path;
use crate::{named, progress_bar, Failure};
use clap::{Args, ValueEnum};
use glint_grade::class::{self, ClassGrades, Entry, Progress};
use glint_grade::course::{Course, Scenes};
use glint_grade::parts::{self, Part};
use glint_grade::report::ReportRow;
use glint_grade::{text, Cache, GradeError, StatedSettings, TestOptions};
use glint_integrator::SamplePattern;
use indicatif::ProgressBar;
use std::path::{Path, PathBuf};

#[derive(Args)]
#[command(
    after_help = "Exit status: 0 when every submission passes, 1 when one fails, is \
                  unreadable for grading (its format lost what the test needs) or \
                  cannot be read, 2 for bad input (flags, scene, manifest, output paths), \
                  3 for a failure of Glint's own, 128 + the signal's number when \
                  stopped (Ctrl-C, SIGTERM; a report being made is removed). The test \
                  and its assumptions: docs/grading.md."
)]
pub(crate) struct GradeArgs {
    /// The scene the submissions render (TOML), then the submitted images
    /// (PNG, JPEG, BMP, TGA, PPM/PGM, Radiance HDR, OpenEXR or PFM, told by
    /// content), each graded at its own resolution through what its format
    /// did to it
    #[arg(value_name = "SCENE.toml SUBMISSION")]
    inputs: Vec<PathBuf>,

    /// Grade a class: a folder of DIR/STUDENT/SCENE.png (the scene named by
    /// the file's stem) or a CSV manifest with the columns student, scene,
    /// file and optionally spp, sampler, light_samples, light_sampler, note
    #[arg(long, value_name = "DIR|MANIFEST.csv", conflicts_with = "inputs")]
    class: Option<PathBuf>,

    /// Where a class's scene names are looked up (NAME is DIR/NAME.toml)
    /// [default: the folder holding the class folder or manifest]
    #[arg(
        long,
        value_name = "DIR",
        requires = "class",
        conflicts_with = "course"
    )]
    scenes: Option<PathBuf>,

    /// The course's scenes at the report's settings: scene names are those of
    /// course/course.toml (set1, set2, set3, environment), each graded with
    /// the settings it gives (the report's 256 samples per pixel and 256 light
    /// samples) unless a manifest or these flags say otherwise
    #[arg(long, requires = "class")]
    course: bool,

    /// The submissions' camera samples per pixel, if known
    #[arg(long, value_name = "N")]
    spp: Option<u32>,

    /// Where the submissions' camera samples fall in the pixel, if known (the
    /// pixel pattern only; the light's is --light-sampler): grid (cell centres
    /// of a √N × √N grid: its expected value is that quadrature's, so a grid
    /// must be stated), random, stratified or sobol (unbiased: any of them
    /// has the same expected value)
    #[arg(long, value_name = "PATTERN", value_parser = named(&SamplePattern::NAMES, SamplePattern::from_name))]
    sampler: Option<SamplePattern>,

    /// The submissions' samples per area light per camera sample, if known
    #[arg(long, value_name = "N")]
    light_samples: Option<u32>,

    /// Where the submissions' light samples fall, if known (grid, random,
    /// stratified, sobol)
    #[arg(long, value_name = "PATTERN", value_parser = named(&SamplePattern::NAMES, SamplePattern::from_name))]
    light_sampler: Option<SamplePattern>,

    /// The chance of failing a correct submission the test allows, over all
    /// its regions
    #[arg(long, value_name = "A", default_value_t = 0.01, value_parser = parse_alpha)]
    alpha: f64,

    /// The side of the test's fine blocks in pixels [default: a 32nd of the
    /// image's shorter side, at least 8]
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(4..=4096))]
    block: Option<u32>,

    /// Where rendered references are kept between runs [default:
    /// $XDG_CACHE_HOME/glint/grade or ~/.cache/glint/grade]
    #[arg(long, value_name = "DIR")]
    cache: Option<PathBuf>,

    /// Render the references again instead of reading the cache
    #[arg(long)]
    no_cache: bool,

    /// List the classic mistakes a failing submission is tested against
    /// (id, stage, how Glint renders it, what it is) and exit
    #[arg(long, exclusive = true)]
    mistakes: bool,

    /// Do not test failing submissions against the classic mistakes (which
    /// renders each mistake once per scene, resolution and settings)
    #[arg(long)]
    no_mistakes: bool,

    /// What to print: table (and, for one submission, every rejected region),
    /// csv or json
    #[arg(long, value_name = "FORMAT", value_enum, default_value_t = Format::Table)]
    format: Format,

    /// Write the heat map of the one submission to this PNG file
    #[arg(long, value_name = "FILE.png")]
    heatmap: Option<PathBuf>,

    /// Write a report folder: index.html (thumbnails, heat maps, a verdict per
    /// scene, sortable columns; works offline), grades.csv, grades.json; with
    /// --part, the part's folder (part.json and its images)
    #[arg(long, value_name = "DIR")]
    report: Option<PathBuf>,

    /// Grade part I of N of the class (submissions I, I+N, I+2N, ... in
    /// class order) into the part folder --report DIR, to be merged with
    /// --merge; exits 0 once graded, whatever the verdicts. With
    /// --references-only: reference sets I, I+N, ... (docs/cluster.md)
    #[arg(long, value_name = "I/N", requires = "class", value_parser = glint_grade::parts::Part::parse)]
    part: Option<Part>,

    /// Render the references the class needs into the cache (--cache), and
    /// grade nothing: the first step of a class graded in parts
    #[arg(long, requires = "class", conflicts_with_all = ["report", "heatmap", "no_cache"])]
    references_only: bool,

    /// Merge the part folders of a class graded in parts (--part I/N) into
    /// what a single run prints and writes (--format, --report)
    #[arg(long, value_name = "PART-DIR", num_args = 1.., conflicts_with_all = [
        "inputs", "class", "stages", "heatmap", "part", "references_only", "cache", "no_cache",
        "spp", "sampler", "light_samples", "light_sampler", "alpha", "block",
    ])]
    merge: Vec<PathBuf>,

    /// Worker threads [default: one per core]; the grades are the same for
    /// any count
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=1024))]
    threads: Option<u32>,

    /// Stage by stage: with --write, write test vectors of SCENE's stages
    /// (camera, intersection, texture, lighting, film: inputs and Glint's
    /// outputs, JSON and CSV); with --answers, check a student's answers
    /// (docs/grading-stages.md)
    #[arg(long, conflicts_with_all = ["class", "report", "heatmap"])]
    stages: bool,

    /// With --stages: the folder to write the test vectors to
    #[arg(
        long,
        value_name = "DIR",
        requires = "stages",
        conflicts_with = "answers"
    )]
    write: Option<PathBuf>,

    /// With --stages: the folder of the student's answers (STAGE.csv or
    /// STAGE.json)
    #[arg(long, value_name = "DIR", requires = "stages")]
    answers: Option<PathBuf>,

    /// With --stages: cases per stage [default: 64]; --answers must be given
    /// the N the test vectors were written with
    #[arg(long, value_name = "N", requires = "stages", value_parser = clap::value_parser!(u32).range(1..=10_000))]
    cases: Option<u32>,
}

impl GradeArgs {
    /// The flags `--stages` reads.
    fn stage_args(&self) -> Result<crate::grade_stages::StageArgs, Failure> {
        let [scene] = &self.inputs[..] else {
            return Err(Failure::Input(
                "glint grade --stages takes one scene: glint grade --stages SCENE.toml --write DIR (or --answers DIR)".into(),
            ));
        };
        if self.format == Format::Csv {
            return Err(Failure::Input(
                "glint grade --stages prints a table or JSON (--format json); its CSV files are the test vectors themselves".into(),
            ));
        }
        if self.write.is_none() == self.answers.is_none() {
            return Err(Failure::Input(
                "glint grade --stages needs --write DIR (test vectors) or --answers DIR (a student's answers)".into(),
            ));
        }
        Ok(crate::grade_stages::StageArgs {
            scene: scene.clone(),
            write: self.write.clone(),
            answers: self.answers.clone(),
            cases: self.cases,
            format_json: self.format == Format::Json,
        })
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
enum Format {
    Table,
    Csv,
    Json,
}

fn parse_alpha(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(a) if a > 0.0 && a < 1.0 => Ok(a),
        _ => Err(format!(
            "expected a probability between 0 and 1 (exclusive), got \"{}\"",
            text::shorten(text)
        )),
    }
}

pub(crate) fn grade(args: &GradeArgs) -> Result<(), Failure> {
    if args.stages {
        return crate::grade_stages::run(&args.stage_args()?);
    }
    if args.mistakes {
        crate::output::say(&glint_grade::report::catalogue());
        return Ok(());
    }
    let Some(threads) = args.threads else {
        return grade_or_merge(args);
    };
    rayon::ThreadPoolBuilder::new()
        .num_threads(threads as usize)
        .build()
        .map_err(|e| Failure::Other(format!("cannot start {threads} threads: {e}")))?
        .install(|| grade_or_merge(args))
}

fn grade_or_merge(args: &GradeArgs) -> Result<(), Failure> {
    if !args.merge.is_empty() {
        return merge(args);
    }
    if args.part.is_some() && args.report.is_none() && !args.references_only {
        return Err(Failure::Input(
            "--part grades into a part folder: give it with --report DIR".into(),
        ));
    }
    let stated = stated(args)?;
    let (entries, scenes, base) = entries(args, &stated)?;
    check_outputs(args, &entries)?;
    if let Some(part) = args.part.filter(|_| !args.references_only) {
        check_part_count(part, entries.len())?;
    }
    let options = class::ClassOptions {
        test: TestOptions {
            alpha: args.alpha,
            block: args.block,
        },
        cache: cache(args)?,
        mistakes: !args.no_mistakes,
    };
    let bar = GradeProgress::new();
    if args.references_only {
        return references_only(&entries, (&scenes, &base), &options, (&bar, args.part));
    }
    let class_entries = entries.len();
    let fingerprint = parts::class_fingerprint(&entries, &class_options(args));
    let (entries, part) = match args.part {
        Some(part) => (part_entries(part, entries), Some(part)),
        None => (entries, None),
    };
    // The report is made in a folder of its own beside the one asked for,
    // and takes its place only when whole: a failed run leaves the old one.
    let staging = args.report.as_deref().map(Staging::new).transpose()?;
    let report = staging.as_ref().map(|s| s.dir.path());
    let on_graded = |i: usize, row: &class::Row, s: &glint_grade::Submission, g: &class::Group| {
        if let Some(dir) = report {
            let index = part.map_or(i, |p| p.submission(i));
            glint_grade::html::write_images(dir, index, row, s, g)?;
        }
        Ok(())
    };
    let on_diagnosed = |i: usize, fit: &[glam::Vec3], size: glam::UVec2| match report {
        Some(dir) => {
            let index = part.map_or(i, |p| p.submission(i));
            glint_grade::html::write_fit_image(dir, index, size, fit)
        }
        None => Ok(()),
    };
    let hooks = class::Hooks {
        on_graded: &on_graded,
        on_diagnosed: &on_diagnosed,
    };
    let grades =
        class::grade_class(&entries, &scenes, &base, &options, &bar, hooks).map_err(failure)?;
    bar.finish();
    if let Some(part) = part {
        let staging = staging.expect("--part requires --report");
        let file = parts::part_file(fingerprint, part, class_entries, &grades);
        parts::write_part(staging.dir.path(), &file).map_err(failure)?;
        staging.finish()?;
        // A part's verdicts are the merge's to report.
        crate::output::say(&glint_grade::report::table(&glint_grade::report::rows(
            &grades,
        )));
        return Ok(());
    }
    if let Some(path) = &args.heatmap {
        write_heatmap(path, &grades)?;
    }
    let rows = glint_grade::report::rows(&grades);
    if let Some(staging) = staging {
        glint_grade::html::write_report(staging.dir.path(), &rows).map_err(failure)?;
        staging.finish()?;
    }
    match (&grades.rows[..], &args.class) {
        ([row], None) if args.format == Format::Table => print_details(row),
        _ => print_rows(args.format, &rows),
    }
    verdict(&rows)
}

/// How many submissions the class of `args` (`--class`) has, and of how
/// many scenes: its folder or manifest read and checked, as a run would
/// before any work.
pub(crate) fn class_size(args: &GradeArgs) -> Result<(usize, usize), Failure> {
    let stated = stated(args)?;
    let entries = entries(args, &stated)?.0;
    let scenes: std::collections::BTreeSet<&str> =
        entries.iter().map(|e| e.scene.as_str()).collect();
    Ok((entries.len(), scenes.len()))
}

/// Exit status 0 when every submission passed, else 1.
fn verdict(rows: &[ReportRow]) -> Result<(), Failure> {
    match rows.iter().all(ReportRow::passed) {
        true => Ok(()),
        false => Err(Failure::Verdict(None)),
    }
}

/// `--references-only`: the references (of the reference sets of `part`)
/// rendered into the cache.
fn references_only(
    entries: &[Entry],
    (scenes, base): (&Scenes, &Path),
    options: &class::ClassOptions,
    (bar, part): (&GradeProgress, Option<Part>),
) -> Result<(), Failure> {
    let Some(dir) = &options.cache.dir else {
        return Err(Failure::Input(
            "--references-only renders into the reference cache, and there is none here; give --cache DIR".into(),
        ));
    };
    let (mine, sets) = class::render_references(entries, scenes, base, options, bar, &|set| {
        part.is_none_or(|p| p.has(set))
    })
    .map_err(failure)?;
    bar.finish();
    let which = match part {
        Some(part) => format!("{mine} of the {sets} reference sets (part {part})"),
        None => format!("{sets} reference sets"),
    };
    crate::output::say(&format!(
        "{which} for {} submissions are in {}\n",
        entries.len(),
        dir.display()
    ));
    Ok(())
}

/// Refuses more parts than the class has submissions.
fn check_part_count(part: Part, submissions: usize) -> Result<(), Failure> {
    match part.count > submissions {
        true => Err(Failure::Input(format!(
            "--part {part}: the class has {submissions} submissions, one per part at most; use at most {submissions} parts"
        ))),
        false => Ok(()),
    }
}

/// The class's submissions that are `part`'s, in class order.
fn part_entries(part: Part, entries: Vec<Entry>) -> Vec<Entry> {
    entries
        .into_iter()
        .enumerate()
        .filter(|(i, _)| part.has(*i))
        .map(|(_, e)| e)
        .collect()
}

/// The options that decide a class's grades beyond its submissions: the
/// parts of a class must agree on them.
fn class_options(args: &GradeArgs) -> String {
    format!(
        "class {:?}, scenes {:?}, course {}, alpha {}, block {:?}",
        args.class, args.scenes, args.course, args.alpha, args.block
    )
}

/// `--merge`: the parts' rows and images, reported as a single run would.
fn merge(args: &GradeArgs) -> Result<(), Failure> {
    if let Some(dir) = &args.report {
        check_report_dir(dir, "--report")?;
    }
    let merged = parts::merge(&args.merge).map_err(failure)?;
    if let Some(report) = &args.report {
        let staging = Staging::new(report)?;
        parts::copy_images(&merged, staging.dir.path()).map_err(failure)?;
        glint_grade::html::write_report(staging.dir.path(), &merged.rows).map_err(failure)?;
        staging.finish()?;
    }
    print_rows(args.format, &merged.rows);
    verdict(&merged.rows)
}

/// A report folder being made: a temporary folder beside `target`, moved into
/// its place when finished (an old report moved aside first, then removed).
/// Interrupted (SIGINT, SIGTERM: Ctrl-C, a Slurm requeue or time limit),
/// the run removes it and ends with the signal's status (128 + its number),
/// never in the middle of putting the report in place.
struct Staging {
    dir: tempfile::TempDir,
    target: PathBuf,
    /// Held while the report is put in place; a signal waits for it.
    placing: std::sync::Arc<std::sync::Mutex<()>>,
}

impl Staging {
    fn new(target: &Path) -> Result<Staging, Failure> {
        let parent = target
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        // Watched before the folder exists: a signal between the two would
        // otherwise end the process the default way and leave the folder.
        let signals = watch_signals()?;
        let dir = tempfile::Builder::new()
            .prefix(".glint-report-")
            .tempdir_in(parent)
            .map_err(|e| {
                Failure::Input(format!(
                    "{}: --report: cannot write there: {e}",
                    target.display()
                ))
            })?;
        let placing = std::sync::Arc::new(std::sync::Mutex::new(()));
        remove_on_signal(signals, dir.path(), std::sync::Arc::clone(&placing))?;
        Ok(Staging {
            dir,
            target: target.to_owned(),
            placing,
        })
    }

    fn finish(self) -> Result<(), Failure> {
        let _placing = self.placing.lock();
        let fail = |e: std::io::Error| {
            Failure::Internal(format!(
                "{}: cannot put the report in place: {e}",
                self.target.display()
            ))
        };
        let old = self.target.exists().then(|| {
            let parent = self.dir.path().parent().expect("made in a folder");
            parent.join(format!(
                ".glint-report-old-{}",
                self.dir
                    .path()
                    .file_name()
                    .map_or("".into(), |n| n.to_string_lossy())
            ))
        });
        if let Some(old) = &old {
            std::fs::rename(&self.target, old).map_err(fail)?;
        }
        let made = self.dir.keep();
        if let Err(e) = std::fs::rename(&made, &self.target) {
            if let Some(old) = &old {
                let _ = std::fs::rename(old, &self.target);
            }
            let _ = std::fs::remove_dir_all(&made);
            return Err(fail(e));
        }
        if let Some(old) = old {
            let _ = std::fs::remove_dir_all(old);
        }
        Ok(())
    }
}

/// SIGINT and SIGTERM caught from now on (kept until handled).
fn watch_signals() -> Result<signal_hook::iterator::Signals, Failure> {
    use signal_hook::consts::{SIGINT, SIGTERM};
    signal_hook::iterator::Signals::new([SIGINT, SIGTERM])
        .map_err(|e| Failure::Other(format!("cannot watch for signals: {e}")))
}

/// Ends the process on the first of `signals` with the signal's status,
/// after removing `dir` (unless it was put in place meanwhile, which
/// `placing` guards).
fn remove_on_signal(
    mut signals: signal_hook::iterator::Signals,
    dir: &Path,
    placing: std::sync::Arc<std::sync::Mutex<()>>,
) -> Result<(), Failure> {
    let dir = dir.to_owned();
    std::thread::Builder::new()
        .name("signals".into())
        .spawn(move || {
            if let Some(signal) = signals.forever().next() {
                let _placed_or_not = placing.lock();
                let _ = std::fs::remove_dir_all(&dir);
                std::process::exit(128 + signal);
            }
        })
        .map_err(|e| Failure::Other(format!("cannot watch for signals: {e}")))?;
    Ok(())
}

/// The settings the command line states for every submission (a manifest's
/// cells and a course's presets fill what it leaves unknown).
fn stated(args: &GradeArgs) -> Result<StatedSettings, Failure> {
    let stated = StatedSettings {
        spp: args.spp,
        pixel_pattern: args.sampler,
        light_samples: args.light_samples,
        light_pattern: args.light_sampler,
    };
    // A grid without its count may be completed by a manifest or a course.
    if let Err(e @ glint_grade::hypothesis::StatedError::Zero { .. }) = stated.validate() {
        return Err(Failure::Input(format!("the submissions' settings: {e}")));
    }
    Ok(stated)
}

/// The submissions, where their scenes are looked up, and what scene paths
/// are relative to.
fn entries(
    args: &GradeArgs,
    stated: &StatedSettings,
) -> Result<(Vec<Entry>, Scenes, PathBuf), Failure> {
    if let Some(class) = &args.class {
        let base = class
            .parent()
            .filter(|p| !p.as_os_str().is_empty())
            .unwrap_or(Path::new("."))
            .to_owned();
        let scenes = match (&args.scenes, args.course) {
            (Some(dir), _) if !dir.is_dir() => {
                return Err(Failure::Input(format!(
                    "{}: --scenes: not a folder",
                    dir.display()
                )))
            }
            (Some(dir), _) => Scenes::Folder(dir.clone()),
            (None, true) => Scenes::Course(Course::load(&course_index()?).map_err(failure)?),
            (None, false) => Scenes::Folder(base.clone()),
        };
        let entries = match class.is_dir() {
            true => class::entries_from_folder(class, stated),
            false if class.is_file() => class::entries_from_manifest(class, stated),
            false => Err(GradeError::Input(format!(
                "{}: --class: no such folder or manifest",
                class.display()
            ))),
        }
        .map_err(failure)?;
        return Ok((entries, scenes, base));
    }
    let Some((scene, submissions)) = args.inputs.split_first() else {
        return Err(Failure::Input(
            "give a scene and the images to grade (glint grade SCENE.toml IMAGE…), or --class"
                .into(),
        ));
    };
    if scene.extension().and_then(|e| e.to_str()) != Some("toml") {
        return Err(Failure::Input(format!(
            "{}: the first argument is the scene, a .toml file",
            scene.display()
        )));
    }
    if submissions.is_empty() {
        return Err(Failure::Input(format!(
            "{}: no images to grade; give them after the scene",
            scene.display()
        )));
    }
    let entries = class::entries_of_scene(scene, submissions, stated);
    // The scene and images are named on the command line: a bad one is bad
    // input, found before any reference is rendered. The scene is loaded
    // once, here, and graded against as loaded.
    let loaded = glint_grade::GradeScene::load(scene).map_err(failure)?;
    for file in submissions {
        glint_grade::Submission::load(file).map_err(Failure::Input)?;
    }
    let scenes = Scenes::Loaded(std::sync::Arc::new(loaded));
    Ok((entries, scenes, PathBuf::new()))
}

/// The course index: `course/course.toml` in the current folder, else in
/// the repository this binary was built from.
fn course_index() -> Result<PathBuf, Failure> {
    let here = PathBuf::from("course/course.toml");
    let built = Path::new(env!("CARGO_MANIFEST_DIR")).join("../course/course.toml");
    [here, built].into_iter().find(|p| p.is_file()).ok_or_else(|| {
        Failure::Input(
            "--course: no course/course.toml here or in the repository Glint was built from; give --scenes DIR".into(),
        )
    })
}

/// The reference cache, made ready before any work: `--cache DIR` must be
/// a folder that can be made and written (else bad input); the default one
/// that cannot is not used, with a note.
fn cache(args: &GradeArgs) -> Result<Cache, Failure> {
    if args.no_cache {
        return Ok(Cache { dir: None });
    }
    if let Some(dir) = &args.cache {
        usable_cache(dir)
            .map_err(|e| Failure::Input(format!("{}: --cache: {e}", dir.display())))?;
        return Ok(Cache {
            dir: Some(dir.clone()),
        });
    }
    let base = std::env::var_os("XDG_CACHE_HOME")
        .map(PathBuf::from)
        .filter(|p| p.is_absolute())
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")));
    let dir = base.map(|b| b.join("glint").join("grade"));
    match dir.as_deref().map(usable_cache) {
        Some(Ok(())) => Ok(Cache { dir }),
        Some(Err(e)) => {
            crate::output::tell(&format!(
                "glint: note: not caching references: {}: {e}",
                dir.expect("some").display()
            ));
            Ok(Cache { dir: None })
        }
        None => Ok(Cache { dir: None }),
    }
}

/// Makes `dir` if need be and checks that files can be written in it.
fn usable_cache(dir: &Path) -> Result<(), String> {
    if dir.exists() && !dir.is_dir() {
        return Err("not a folder".into());
    }
    std::fs::create_dir_all(dir).map_err(|e| format!("cannot make the folder: {e}"))?;
    tempfile::Builder::new()
        .prefix(".glint-probe-")
        .tempfile_in(dir)
        .map_err(|e| format!("cannot write there: {e}"))?;
    Ok(())
}

/// Every output path, before any work.
fn check_outputs(args: &GradeArgs, entries: &[Entry]) -> Result<(), Failure> {
    if let Some(path) = &args.heatmap {
        if entries.len() != 1 {
            return Err(Failure::Input(format!(
                "{}: --heatmap writes one submission's map, and there are {}; use --report DIR for many",
                path.display(),
                entries.len()
            )));
        }
        check_heatmap_path(path, &[entries[0].file.as_path()])?;
    }
    if let Some(dir) = &args.report {
        check_report_dir(dir, "--report")?;
    }
    Ok(())
}

/// A report folder: new, empty, or an earlier report's (or part's), which
/// the new one replaces whole.
pub(crate) fn check_report_dir(dir: &Path, flag: &str) -> Result<(), Failure> {
    glint_grade::output::check_dir(dir, flag).map_err(failure)?;
    let is_empty = |d: &Path| std::fs::read_dir(d).is_ok_and(|mut e| e.next().is_none());
    let is_report =
        |d: &Path| d.join("grades.json").is_file() || d.join(parts::PART_FILE).is_file();
    if dir.is_dir() && !is_empty(dir) && !is_report(dir) {
        return Err(Failure::Input(format!(
            "{}: {flag}: the folder holds files that are not a report of glint grade's, and a report replaces its folder whole; choose a new folder",
            dir.display()
        )));
    }
    Ok(())
}

fn write_heatmap(path: &Path, grades: &ClassGrades) -> Result<(), Failure> {
    let row = &grades.rows[0];
    let (class::Outcome::Graded(grade), Some(g)) = (&row.outcome, row.group) else {
        return Ok(());
    };
    let submission = glint_grade::Submission::load(Path::new(&row.file)).map_err(Failure::Other)?;
    let group = &grades.groups[g];
    let pixels = glint_grade::heatmap::heatmap(grade, &submission.film, &group.references.objects);
    glint_grade::html::save_png(path, submission.resolution(), &pixels).map_err(failure)
}

/// One submission's every rejected region, or why it was not graded.
fn print_details(row: &class::Row) {
    let text = match &row.outcome {
        class::Outcome::Graded(g) => glint_grade::report::details(g, 10),
        class::Outcome::Unreadable { message } => format!("{}: error: {message}\n", row.file),
    };
    crate::output::say(&text);
}

/// The class in `format`. A reader that stops early (`| head`) is not an
/// error.
fn print_rows(format: Format, rows: &[ReportRow]) {
    let text = match format {
        Format::Csv => glint_grade::report::csv(rows),
        Format::Json => {
            serde_json::to_string_pretty(&glint_grade::report::json(rows)).expect("JSON") + "\n"
        }
        Format::Table => glint_grade::report::table(rows),
    };
    crate::output::say(&text);
}

fn failure(e: GradeError) -> Failure {
    match e {
        GradeError::Input(m) => Failure::Input(m),
        GradeError::Internal(m) => Failure::Internal(m),
    }
}

/// A progress bar over the submissions, and the references' renders as
/// lines above it (on a terminal only).
struct GradeProgress {
    bar: Option<ProgressBar>,
}

impl GradeProgress {
    fn new() -> GradeProgress {
        GradeProgress {
            bar: progress_bar("{spinner} grading {pos}/{len} [{bar:30}] {elapsed}"),
        }
    }

    fn finish(&self) {
        if let Some(bar) = &self.bar {
            bar.finish_and_clear();
        }
    }
}

impl Progress for GradeProgress {
    fn rendering(&self, what: &str) {
        if let Some(bar) = &self.bar {
            bar.println(what);
        }
    }

    fn graded(&self, done: usize, total: usize) {
        if let Some(bar) = &self.bar {
            bar.set_length(total as u64);
            bar.set_position(done as u64);
        }
    }
}
