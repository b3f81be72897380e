//! `glint farm ENGINE grade`: a class's grading as a farm job. First
//! `references.sh` renders every reference the class needs into a cache the
//! machines share (`glint grade --references-only`), once; then one task per
//! part (`grade-part.sh I`: `glint grade --part I/N`, submissions I, I+N, …)
//! reads them from there; then `merge-grades.sh` merges the parts into the
//! report a single run writes (`glint grade --merge`).

use super::script::{
    check_managed, file_stem, or_default, parse_command, quote, quote_str, Farm, FirstStep,
};
use crate::{Command, Failure};
use clap::Args;
use std::path::{Path, PathBuf};

#[derive(Args)]
pub(crate) struct FarmGrade {
    /// The class: a folder of DIR/STUDENT/SCENE.png or a CSV manifest, as
    /// glint grade --class takes it
    #[arg(long, value_name = "DIR|MANIFEST.csv")]
    class: PathBuf,

    /// How many parts (tasks): part I grades submissions I, I+N, I+2N, ...
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..))]
    parts: u32,

    /// The merged report folder: index.html, grades.csv, grades.json, images
    /// [default: CLASS-NAME-report in the current directory]
    #[arg(short, long, value_name = "DIR")]
    output: Option<PathBuf>,

    /// Where the scripts, the parts (parts/) and logs (logs/) go [default:
    /// CLASS-NAME.grade-farm in the current directory]
    #[arg(long, value_name = "DIR")]
    dir: Option<PathBuf>,

    /// The reference cache every task reads, on a file system they all see
    /// [default: DIR/cache]
    #[arg(long, value_name = "DIR")]
    cache: Option<PathBuf>,

    /// Tasks rendering the references before the parts: task I renders
    /// reference sets I, I+R, ... (one per scene, resolution and settings,
    /// in order of first use) [default: the class's scene count]
    #[arg(long, value_name = "R", value_parser = clap::value_parser!(u32).range(1..))]
    reference_tasks: Option<u32>,

    /// Options for every glint grade (after --, e.g. -- --scenes scenes
    /// --spp 16): how the class is graded
    #[arg(last = true, value_name = "GRADE-OPTIONS")]
    grade_options: Vec<String>,
}

/// Options `glint farm` sets for every step itself.
const MANAGED: [&str; 13] = [
    "--class",
    "--part",
    "--report",
    "--merge",
    "--references-only",
    "--cache",
    "--no-cache",
    "--threads",
    "--heatmap",
    "--format",
    "--stages",
    "--write",
    "--answers",
];

/// A class in parts, checked, with every path absolute.
pub(crate) struct ClassPlan {
    glint: PathBuf,
    /// Where glint farm ran: the steps run there, so that the options'
    /// relative paths (--scenes) mean what they meant.
    here: PathBuf,
    class: PathBuf,
    parts: u32,
    reference_tasks: u32,
    output: PathBuf,
    dir: PathBuf,
    cache: PathBuf,
    grade_options: Vec<String>,
}

impl ClassPlan {
    /// Checks everything before any file is written: the options (as `glint
    /// grade` parses them), the class (its folder or manifest read), the
    /// part count against its submissions, and the paths.
    pub(crate) fn new(args: &FarmGrade) -> Result<ClassPlan, Failure> {
        check_managed("grade", &args.grade_options, &MANAGED)?;
        let stem = file_stem(&args.class, "class");
        let dir = or_default(&args.dir, format!("{stem}.grade-farm"));
        let output = or_default(&args.output, format!("{stem}-report"));
        let cache = args.cache.clone().unwrap_or_else(|| dir.join("cache"));
        for (flag, folder) in [("--dir", &dir), ("--cache", &cache)] {
            glint_camera::check_output_folder(folder)
                .map_err(|e| Failure::Input(format!("{flag} {}: {e}", folder.display())))?;
        }
        crate::grade::check_report_dir(&output, "-o")?;
        let grade = parse_grade(&args.class, &dir, &args.grade_options)?;
        let (submissions, scenes) = crate::grade::class_size(&grade)?;
        if args.parts as usize > submissions {
            return Err(Failure::Input(format!(
                "--parts {}: the class has {submissions} submissions, one per part at most; use at most {submissions} parts",
                args.parts
            )));
        }
        let absolute = |path: &Path| std::path::absolute(path).unwrap_or_else(|_| path.to_owned());
        let glint = crate::program()
            .map_err(|e| Failure::Other(format!("cannot find the glint executable: {e}")))?;
        Ok(ClassPlan {
            glint,
            here: absolute(Path::new(".")),
            class: absolute(&args.class),
            parts: args.parts,
            reference_tasks: args.reference_tasks.unwrap_or(scenes as u32),
            output: absolute(&output),
            dir: absolute(&dir),
            cache: absolute(&cache),
            grade_options: args.grade_options.clone(),
        })
    }

    /// The job: the references, then a task per part, then the merge.
    pub(crate) fn farm(&self) -> Farm {
        let folders = [
            self.dir.clone(),
            self.dir.join("parts"),
            self.dir.join("logs"),
            self.cache.clone(),
        ];
        let output_folder = self.output.parent().map(Path::to_owned);
        Farm {
            first: Some(FirstStep {
                kind: "references",
                script: "references.sh",
                tasks: self.reference_tasks,
                text: self.references_script(),
            }),
            kind: "grade",
            merge_kind: "merge",
            task_script: "grade-part.sh",
            merge_script: "merge-grades.sh",
            scene: self.class.clone(),
            dir: self.dir.clone(),
            tasks: self.parts,
            what: format!("{} parts of the class {}", self.parts, self.class.display()),
            folders: folders.into_iter().chain(output_folder).collect(),
            task_text: self.part_script(),
            merge_text: self.merge_script(),
        }
    }

    fn part_dir(&self, part: &str) -> String {
        format!("{}/part-{part}", quote(&self.dir.join("parts")))
    }

    /// The start every step's script shares: where it runs, and the class.
    fn preamble(&self, what: &str) -> String {
        format!(
            "#!/bin/bash\n# {what} (written by glint farm).\nset -euo pipefail\ncd {here}\n",
            here = quote(&self.here)
        )
    }

    /// `glint grade --class CLASS --cache CACHE`, then the grade options.
    fn grade_command(&self, flags: &str) -> String {
        let options: String = self
            .grade_options
            .iter()
            .map(|o| format!(" {}", quote_str(o)))
            .collect();
        format!(
            "{glint} grade --class {class} --cache {cache}{flags}{options}",
            glint = quote(&self.glint),
            class = quote(&self.class),
            cache = quote(&self.cache),
        )
    }

    /// `references.sh I`: reference sets I, I+R, … of the class, into the
    /// cache.
    fn references_script(&self) -> String {
        format!(
            r#"{preamble}task="$1"
threads="${{SLURM_CPUS_PER_TASK:-1}}"
exec {command} --part "$task/{tasks}" --threads "$threads"
"#,
            preamble = self.preamble(&format!(
                "Renders reference sets I, I+{tasks}, ... of the class {} into its cache. Usage: references.sh I",
                self.class.display(),
                tasks = self.reference_tasks
            )),
            command = self.grade_command(" --references-only"),
            tasks = self.reference_tasks,
        )
    }

    /// `grade-part.sh I`: part I into its folder; it exits 0 once graded,
    /// whatever the verdicts. Run again, it grades the part again, to the
    /// same rows.
    fn part_script(&self) -> String {
        format!(
            r#"{preamble}part="$1"
threads="${{SLURM_CPUS_PER_TASK:-1}}"
exec {command} --part "$part/{parts}" --report {part_dir} --threads "$threads"
"#,
            preamble = self.preamble(&format!(
                "Grades part I of {} of the class {}. Usage: grade-part.sh I",
                self.parts,
                self.class.display()
            )),
            command = self.grade_command(""),
            parts = self.parts,
            part_dir = self.part_dir("\"$part\""),
        )
    }

    /// `merge-grades.sh`: the parts there are, merged into the report;
    /// `glint grade --merge` names any missing. Failed submissions are the
    /// report's news, not the step's failure.
    fn merge_script(&self) -> String {
        format!(
            r#"{preamble}parts=()
for part in $(seq 0 {last}); do
  d={parts_dir}/part-"$part"
  if [ -e "$d/part.json" ]; then parts+=("$d"); fi
done
if [ ${{#parts[@]}} -eq 0 ]; then echo "no parts in "{parts_dir} >&2; exit 2; fi
status=0
{glint} grade --merge "${{parts[@]}}" --report {output} || status=$?
# 1: some submissions fail; the report says which.
if [ $status -eq 1 ]; then status=0; fi
exit $status
"#,
            preamble = self.preamble(&format!(
                "Merges the {} parts of the class {} into its report",
                self.parts,
                self.class.display()
            )),
            last = self.parts - 1,
            parts_dir = quote(&self.dir.join("parts")),
            glint = quote(&self.glint),
            output = quote(&self.output),
        )
    }
}

/// The parts' `glint grade` command line as `glint grade` parses it.
fn parse_grade(
    class: &Path,
    dir: &Path,
    options: &[String],
) -> Result<crate::grade::GradeArgs, Failure> {
    let part = dir.join("parts").join("part-0");
    let fixed = [
        "--class".into(),
        class.as_os_str().to_owned(),
        "--part".into(),
        "0/1".into(),
        "--report".into(),
        part.into_os_string(),
    ];
    match parse_command("grade", &fixed, options)? {
        Command::Grade(args) => Ok(args),
        _ => unreachable!("parsed as glint grade"),
    }
}
