//! The docs state the rules `glint explain --against` and `glint grade
//! --stages` compare by, and the shadow-ray offsets the test vectors allow:
//! each statement is made here from `glint_explain::rules`' constants and
//! must be in the page, so a changed constant fails until the docs say it.

use glint_explain::rules::{ANGLE, FLOOR, LEVEL, RELATIVE, SHADOW_EPSILON, UNIT};
use std::path::Path;

fn page(name: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../docs")
        .join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The doc's text with its line breaks as spaces, so that a statement may
/// wrap anywhere.
fn flowing(text: &str) -> String {
    text.split_whitespace().collect::<Vec<_>>().join(" ")
}

fn assert_states(name: &str, statements: &[String]) {
    let text = flowing(&page(name));
    for statement in statements {
        assert!(
            text.contains(statement.as_str()),
            "docs/{name} does not state {statement:?} (the rule in commands/explain/src/rules.rs)"
        );
    }
}

#[test]
fn the_stage_grading_page_states_the_tolerances_the_code_applies() {
    assert_states(
        "grading-stages.md",
        &[
            format!("within `{RELATIVE:e}·|Glint's| + {FLOOR:e}`"),
            format!(
                "each component within `{RELATIVE:e}·(Glint's largest |component|) + {FLOOR:e}`"
            ),
            "with `u` compared modulo 1 on spheres".into(),
            format!("at most {ANGLE:e} radians from Glint's, and of length 1 within {UNIT:e}"),
            format!("within {LEVEL} levels"),
            format!(
                "`ε` from {:e} to {:e} of the scene's size",
                SHADOW_EPSILON[0], SHADOW_EPSILON[1]
            ),
        ],
    );
}

#[test]
fn the_against_page_states_the_same_tolerances() {
    assert_states(
        "checking-your-ray-tracer.md",
        &[
            format!("within {RELATIVE:e} × abs(Glint's) + {FLOOR:e}"),
            format!("at most {ANGLE:e} radians from Glint's, and of length 1 within {UNIT:e}"),
            "with `u` modulo 1".into(),
            format!("each component within {RELATIVE:e} × (the largest abs(component) of Glint's) + {FLOOR:e}"),
        ],
    );
}

#[test]
fn the_shadow_ray_rule_states_the_offsets_the_vectors_allow() {
    // The size of the Cornell box as glint-grade measures it (its test
    // `the_cornell_box_is_23_units_across` holds it to this).
    let cornell = 23.0;
    assert_states(
        "scene-format.md",
        &[
            format!(
                "`ε` may be anything from {:e} to {:e} of the scene's size",
                SHADOW_EPSILON[0], SHADOW_EPSILON[1]
            ),
            format!(
                "23 units, so `ε` from {:e} to {:e})",
                (SHADOW_EPSILON[0] * cornell * 1e6).round() / 1e6,
                (SHADOW_EPSILON[1] * cornell * 1e6).round() / 1e6
            ),
            "aim it at `p` from `o`".into(),
            "count a blocker only at `0 < t < |p − o| − ε`".into(),
        ],
    );
}
