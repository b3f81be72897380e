//! Where a class's scene names are looked up: a folder (`NAME` is
//! `DIR/NAME.toml`) or a course index (`course/course.toml`: each
//! `[scenes.NAME]` a scene file and the settings the course renders it with).

use crate::hypothesis::StatedSettings;
use crate::{GradeError, GradeScene};
use glint_integrator::SamplePattern;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// How scene names become scene files and preset settings.
#[derive(Clone, Debug)]
pub enum Scenes {
    /// `NAME` is `DIR/NAME.toml`; no preset settings.
    Folder(PathBuf),
    /// A course index.
    Course(Course),
    /// One scene already loaded (from memory, say): every name means it.
    Loaded(Arc<GradeScene>),
}

/// A course index: its scenes by name.
#[derive(Clone, Debug, PartialEq)]
pub struct Course {
    pub path: PathBuf,
    pub scenes: BTreeMap<String, CourseScene>,
}

/// One scene of a course.
#[derive(Clone, Debug, PartialEq)]
pub struct CourseScene {
    /// The scene file, relative to the current directory.
    pub file: PathBuf,
    pub description: String,
    /// The settings the course renders it with.
    pub stated: StatedSettings,
}

impl Scenes {
    /// The scene file `name` means, and the settings it presets: a path to a
    /// `.toml` file is taken as it is (relative to `base`); a loaded scene is
    /// every name's.
    pub fn resolve(&self, name: &str, base: &Path) -> Result<(PathBuf, StatedSettings), String> {
        match self {
            Scenes::Loaded(scene) => Ok((scene.path.clone(), StatedSettings::default())),
            _ if name.ends_with(".toml") => Ok((base.join(name), StatedSettings::default())),
            Scenes::Folder(dir) => {
                Ok((dir.join(format!("{name}.toml")), StatedSettings::default()))
            }
            Scenes::Course(course) => course
                .scenes
                .get(name)
                .map(|s| (s.file.clone(), s.stated))
                .ok_or_else(|| {
                    let known: Vec<&str> = course.scenes.keys().map(String::as_str).collect();
                    format!(
                        "no scene \"{}\" in {} (it has {})",
                        crate::text::shorten(name),
                        course.path.display(),
                        known.join(", ")
                    )
                }),
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CourseFile {
    scenes: BTreeMap<String, SceneTable>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneTable {
    file: String,
    #[serde(default)]
    description: String,
    spp: Option<u32>,
    sampler: Option<String>,
    light_samples: Option<u32>,
    light_sampler: Option<String>,
}

impl Course {
    /// Reads a course index.
    pub fn load(path: &Path) -> Result<Course, GradeError> {
        let input = |m: String| GradeError::Input(format!("{}: {m}", path.display()));
        let text = glint_scene::read_text(path, glint_scene::MAX_DOCUMENT_BYTES, "a course index")
            .map_err(|e| input(format!("cannot read the course index: {e}")))?;
        let file: CourseFile = toml::from_str(&text).map_err(|e| {
            let at = e.span().map_or(String::new(), |s| {
                let (line, column) = line_column(&text, s.start);
                format!("{line}:{column}: ")
            });
            input(format!("{at}{}", e.message()))
        })?;
        let base = path.parent().unwrap_or(Path::new(""));
        let mut scenes = BTreeMap::new();
        for (name, table) in file.scenes {
            let field = |key: &str| format!("scenes.{name}.{key}");
            let pattern = |key: &str, value: &Option<String>| -> Result<_, GradeError> {
                value
                    .as_deref()
                    .map(|v| {
                        SamplePattern::from_name(v).ok_or_else(|| {
                            input(format!(
                                "{}: \"{}\" is not a pattern; expected one of {}",
                                field(key),
                                crate::text::shorten(v),
                                SamplePattern::NAMES.join(", ")
                            ))
                        })
                    })
                    .transpose()
            };
            let stated = StatedSettings {
                spp: table.spp,
                pixel_pattern: pattern("sampler", &table.sampler)?,
                light_samples: table.light_samples,
                light_pattern: pattern("light_sampler", &table.light_sampler)?,
            };
            stated
                .validate()
                .map_err(|e| input(format!("scenes.{name}: {e}")))?;
            scenes.insert(
                name,
                CourseScene {
                    file: base.join(table.file),
                    description: table.description,
                    stated,
                },
            );
        }
        Ok(Course {
            path: path.to_owned(),
            scenes,
        })
    }
}

/// 1-based line and column of byte `offset` in `text`.
fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn course(text: &str) -> Result<Course, GradeError> {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("course.toml");
        std::fs::write(&path, text).unwrap();
        Course::load(&path)
    }

    #[test]
    fn the_shipped_course_names_the_report_scenes_at_its_settings() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../course/course.toml");
        let course = Course::load(&path).unwrap();
        let names: Vec<&str> = course.scenes.keys().map(String::as_str).collect();
        assert_eq!(names, ["environment", "set1", "set2", "set3"]);
        for scene in course.scenes.values() {
            assert!(scene.file.is_file(), "{}", scene.file.display());
        }
        let (file, stated) = Scenes::Course(course)
            .resolve("set2", Path::new("x"))
            .unwrap();
        assert!(file.ends_with("scenes/cornell-set2.toml"));
        assert_eq!((stated.spp, stated.light_samples), (Some(256), Some(256)));
        assert_eq!(stated.pixel_pattern, None);
    }

    #[test]
    fn bad_indexes_and_names_are_located() {
        let e = course("[scenes.a]\nfile = \"a.toml\"\nsampler = \"gird\"\n").unwrap_err();
        assert!(
            e.to_string()
                .contains("scenes.a.sampler: \"gird\" is not a pattern"),
            "{e}"
        );
        let e = course("[scenes.a]\nfile = \"a.toml\"\nspp = \"x\"\n").unwrap_err();
        assert!(
            e.to_string().contains("course.toml: 3:7: invalid type"),
            "{e}"
        );
        let e = course("[scenes.a]\nfile = \"a.toml\"\nsampler = \"grid\"\n").unwrap_err();
        assert!(e.to_string().contains("give --spp too"), "{e}");
        let c = course("[scenes.a]\nfile = \"a.toml\"\n").unwrap();
        let e = Scenes::Course(c).resolve("b", Path::new("")).unwrap_err();
        assert!(
            e.contains("no scene \"b\"") && e.contains("(it has a)"),
            "{e}"
        );
    }
}
