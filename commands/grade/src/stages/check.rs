//! Checking a student's answers against Glint's vectors: each expected field
//! within its tolerance ([`Check`]), a score per stage, and the first failing
//! case of each stage with `glint explain`'s text for its pixel and sample.

use super::answers::{self, Answer, Answers};
use super::probe;
use super::table::{Case, Check, Field, Value};
use super::{vectors, Stage, StageVectors};
use crate::{GradeError, GradeScene};
use glint_explain::rules::{self, Rule};
use glint_integrator::trace::SampleSelection;
use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// One expected field an answer does not match.
#[derive(Clone, Debug, PartialEq)]
pub struct Difference {
    pub field: Field,
    pub expected: Vec<Value>,
    pub answered: Vec<Answer>,
    /// How far apart, and what the tolerance allows (radians for a
    /// direction's angle; none where a value is missing or must be equal).
    pub apart: Option<f64>,
    pub allowed: Option<f64>,
    /// What is wrong, in words, where the numbers do not say it.
    pub note: Option<&'static str>,
}

/// A stage's first failing case.
#[derive(Clone, Debug, PartialEq)]
pub struct CaseFailure {
    pub case: Case,
    /// The stage's input columns, in order.
    pub inputs: Vec<String>,
    /// Its fields that differ, in layout order.
    pub differences: Vec<Difference>,
    /// The steps that decided the expected values where the stage's own
    /// computation differs from the render's or the numbers alone do not
    /// say it: the texture lookup at the report's level; each shadow verdict
    /// that differs, both blockers named.
    pub steps: Vec<String>,
    /// `glint explain`'s text of the case's pixel and sample, this stage
    /// only (none for the film's chosen values).
    pub explanation: Option<String>,
}

/// One stage's score.
#[derive(Clone, Debug, PartialEq)]
pub struct StageCheck {
    pub stage: Stage,
    /// The answer file read, or none: not answered.
    pub file: Option<PathBuf>,
    /// The stage's cases (not counted for a stage not answered).
    pub total: Option<usize>,
    pub answered: usize,
    pub passed: usize,
    pub first_failure: Option<CaseFailure>,
}

impl StageCheck {
    /// A stage without an answer file.
    fn not_answered(stage: Stage) -> StageCheck {
        StageCheck {
            stage,
            file: None,
            total: None,
            answered: 0,
            passed: 0,
            first_failure: None,
        }
    }

    /// Every answered case passes (an unanswered stage passes).
    pub fn passes(&self) -> bool {
        self.passed == self.answered
    }
}

/// Every stage's score.
#[derive(Clone, Debug, PartialEq)]
pub struct StagesCheck {
    /// The scene's file name.
    pub scene: String,
    pub answers: PathBuf,
    pub cases_requested: u32,
    pub stages: Vec<StageCheck>,
}

impl StagesCheck {
    /// Every answered case of every stage passes.
    pub fn passed(&self) -> bool {
        self.stages.iter().all(StageCheck::passes)
    }
}

/// Checks the answers in `dir` (see [`super::check_answers`]).
pub fn check(scene: &GradeScene, cases: u32, dir: &Path) -> Result<StagesCheck, GradeError> {
    let answered = answer_files(dir)?;
    // Only the answered stages' vectors are made.
    let stages: Vec<Stage> = answered.iter().map(|(s, _)| *s).collect();
    let mut made = vectors(scene, &stages, cases)?.into_iter();
    let mut checks = Vec::new();
    for stage in Stage::ALL {
        let check = match answered.iter().find(|(s, _)| *s == stage) {
            Some((_, file)) => {
                let v = made.next().expect("one vector set per answered stage");
                let ids: BTreeSet<String> = v.cases.iter().map(|c| c.id.clone()).collect();
                score(scene, &v, &answers::read(file, stage, &v.layout, &ids)?)
            }
            None => StageCheck::not_answered(stage),
        };
        checks.push(check);
    }
    Ok(StagesCheck {
        scene: super::scene_name(scene),
        answers: dir.to_owned(),
        cases_requested: cases,
        stages: checks,
    })
}

/// The answered stages and their files in `dir`, in pipeline order; bad
/// input if `dir` is not a folder or holds none.
fn answer_files(dir: &Path) -> Result<Vec<(Stage, PathBuf)>, GradeError> {
    if !dir.is_dir() {
        return Err(GradeError::Input(format!(
            "{}: --answers: no such folder",
            dir.display()
        )));
    }
    let found: Vec<(Stage, PathBuf)> = Stage::ALL
        .iter()
        .filter_map(|&s| Some((s, answers::find(dir, s)?)))
        .collect();
    if found.is_empty() {
        return Err(GradeError::Input(format!(
            "{}: --answers: no answers here: expected STAGE.csv or STAGE.json for a stage of camera, intersection, texture, lighting, film",
            dir.display()
        )));
    }
    Ok(found)
}

/// A stage's score against `answers`.
pub fn score(scene: &GradeScene, v: &StageVectors, answers: &Answers) -> StageCheck {
    let mut check = StageCheck {
        stage: v.stage,
        file: Some(answers.file.clone()),
        total: Some(v.cases.len()),
        answered: 0,
        passed: 0,
        first_failure: None,
    };
    for case in &v.cases {
        let Some(row) = answers.rows.get(&case.id) else {
            continue;
        };
        check.answered += 1;
        let differences: Vec<Difference> = v
            .layout
            .expected
            .iter()
            .filter(|f| !f.optional || f.columns.iter().any(|c| row.contains_key(c)))
            .filter_map(|f| {
                let answered: Vec<Answer> = f
                    .columns
                    .iter()
                    .map(|c| row.get(c).cloned().unwrap_or(Answer::Empty))
                    .collect();
                compare(f, case, &answered)
            })
            .collect();
        if differences.is_empty() {
            check.passed += 1;
        } else if check.first_failure.is_none() {
            check.first_failure = Some(CaseFailure {
                explanation: explain(scene, v.stage, case),
                steps: steps(scene, v.stage, case, row),
                case: case.clone(),
                inputs: v.layout.inputs.clone(),
                differences,
            });
        }
    }
    check
}

/// [`CaseFailure::steps`] of `case`, answered by `row`.
fn steps(
    scene: &GradeScene,
    stage: Stage,
    case: &Case,
    row: &std::collections::BTreeMap<String, Answer>,
) -> Vec<String> {
    let d = &scene.description;
    match stage {
        Stage::Texture => super::texture::expected_steps(&d.scene, case),
        Stage::Lighting => super::lighting::verdict_steps(&d.object_names, case, row),
        _ => Vec::new(),
    }
}

/// `glint explain`'s text of `case`'s pixel and sample, `stage` only.
fn explain(scene: &GradeScene, stage: Stage, case: &Case) -> Option<String> {
    let from = case.from.as_ref()?;
    let d = &scene.description;
    let settings = probe::settings(&d.settings, from.spp);
    let [x, y] = from.pixel;
    let selection = SampleSelection::One(from.sample.into());
    match glint_explain::explain(&d.scene, &settings, x, y, selection) {
        Ok(e) => Some(e.text(Some(stage.explain_stage()))),
        Err(e) => Some(format!("(glint explain failed: {e})")),
    }
}

/// How `answered` differs from `case`'s values of `field`, if it does.
pub fn compare(field: &Field, case: &Case, answered: &[Answer]) -> Option<Difference> {
    let expected: Vec<Value> = field.columns.iter().map(|c| case.get(c).clone()).collect();
    if field.check == Check::Info || expected.iter().all(|e| *e == Value::Empty) {
        return None;
    }
    let differ = |apart: Option<f64>, allowed: Option<f64>, note: Option<&'static str>| {
        Some(Difference {
            field: field.clone(),
            expected: expected.clone(),
            answered: answered.to_vec(),
            apart,
            allowed,
            note,
        })
    };
    if answered.contains(&Answer::Empty) {
        return differ(None, None, Some("no value"));
    }
    if field.check == Check::Exact {
        let equal = expected.iter().zip(answered).all(|(e, a)| same(e, a));
        return if equal {
            None
        } else {
            differ(None, None, None)
        };
    }
    let e: Vec<f64> = expected
        .iter()
        .map(|v| v.number().unwrap_or(f64::NAN))
        .collect();
    let a: Vec<f64> = answered
        .iter()
        .map(|v| match v {
            Answer::Number(x) => *x,
            _ => f64::NAN,
        })
        .collect();
    let (apart, allowed, note) = measure(field.check, &e, &a, case.periodic_u);
    // NaN is never within tolerance.
    if apart <= allowed {
        None
    } else {
        differ(Some(apart), Some(allowed), note)
    }
}

/// Whether an exact answer equals Glint's value.
fn same(expected: &Value, answered: &Answer) -> bool {
    match (expected, answered) {
        (Value::Int(e), Answer::Number(a)) => *e as f64 == *a,
        (Value::Bool(e), Answer::Bool(a)) => e == a,
        (Value::Text(e), Answer::Text(a)) => e == a,
        _ => false,
    }
}

/// How far apart `a` is from `e` under `check` ([`glint_explain::rules`],
/// the rules `glint explain --against` compares by), what it allows, and a
/// note where the figure is not the difference itself.
fn measure(
    check: Check,
    e: &[f64],
    a: &[f64],
    periodic_u: bool,
) -> (f64, f64, Option<&'static str>) {
    let rule = match check {
        Check::Relative => Rule::Relative,
        Check::Vector => Rule::Vector,
        Check::Uv => Rule::Uv {
            u_period: periodic_u.then_some(1.0),
        },
        Check::Level => Rule::Level,
        Check::Direction => Rule::Direction,
        Check::Exact | Check::Info => return (0.0, 0.0, None),
    };
    let gap = rules::measure(rule, e, a);
    (gap.apart, gap.allowed, gap.note)
}

#[cfg(test)]
mod tests {
    use super::super::table::Kind;
    use super::*;

    fn case_with(column: &str, v: Value) -> Case {
        let mut c = Case::new(None);
        c.set(column, v);
        c
    }

    fn n(x: f64) -> Answer {
        Answer::Number(x)
    }

    #[test]
    fn a_relative_value_passes_within_its_tolerance_and_fails_beyond() {
        let f = Field::scalar("t", Kind::Float, Check::Relative);
        let c = case_with("t", Value::Float(20.0));
        assert_eq!(compare(&f, &c, &[n(20.0199)]), None);
        let d = compare(&f, &c, &[n(20.0201)]).unwrap();
        assert!((d.apart.unwrap() - 0.0201).abs() < 1e-9);
        assert!((d.allowed.unwrap() - (0.02 + 1e-6)).abs() < 1e-12);
        assert_eq!(
            compare(&f, &c, &[Answer::Empty]).unwrap().note,
            Some("no value")
        );
        assert!(compare(&f, &c, &[n(f64::NAN)]).is_some());
        // Nothing to check where Glint's value does not apply.
        assert_eq!(
            compare(&f, &case_with("u", Value::Float(1.0)), &[n(5.0)]),
            None
        );
    }

    #[test]
    fn a_direction_is_checked_by_its_angle_and_length() {
        let f = Field::xyz("d", Check::Direction);
        let mut c = Case::new(None);
        c.xyz("d", glam::Vec3::Z);
        let turned = |a: f64| [n(a.sin()), n(0.0), n(a.cos())];
        assert_eq!(compare(&f, &c, &turned(0.9e-3)), None);
        let d = compare(&f, &c, &turned(1.1e-3)).unwrap();
        assert!((d.apart.unwrap() - 1.1e-3).abs() < 1e-9, "{d:?}");
        let long = compare(&f, &c, &[n(0.0), n(0.0), n(2.0)]).unwrap();
        assert_eq!(long.note, Some("not of unit length"));
    }

    #[test]
    fn u_wraps_around_on_spheres_only() {
        let f = Field::uv();
        let mut c = Case::new(None);
        c.uv(glam::Vec2::new(0.9999, 0.5));
        let answer = [n(0.0001), n(0.5)];
        assert!(compare(&f, &c, &answer).is_some());
        c.periodic_u = true;
        assert_eq!(compare(&f, &c, &answer), None);
        // A wrong sign of u is half a turn off, wrapped or not.
        c.uv(glam::Vec2::new(0.3, 0.5));
        assert!(compare(&f, &c, &[n(-0.3), n(0.5)]).is_some());
    }

    #[test]
    fn ids_verdicts_and_codes_must_be_equal() {
        let f = Field::scalar("object", Kind::Int, Check::Exact);
        let c = case_with("object", Value::Int(3));
        assert_eq!(compare(&f, &c, &[n(3.0)]), None);
        assert!(compare(&f, &c, &[n(4.0)]).is_some());
        let f = Field::scalar("verdict", Kind::Text, Check::Exact);
        let c = case_with("verdict", Value::Text("blocked".into()));
        assert_eq!(compare(&f, &c, &[Answer::Text("blocked".into())]), None);
        assert!(compare(&f, &c, &[Answer::Text("visible".into())]).is_some());
        let f = Field::rgb_codes("srgb8");
        let mut c = Case::new(None);
        for k in ["srgb8_r", "srgb8_g", "srgb8_b"] {
            c.int(k, 128);
        }
        assert!(compare(&f, &c, &[n(128.0), n(128.0), n(127.0)]).is_some());
    }
}
