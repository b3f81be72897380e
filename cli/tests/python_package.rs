//! The Python package (`python/`): built into the virtual environment
//! `GLINT_PYTHON_VENV` (or `target/python-venv`, which `.ci/run` makes with
//! maturin, numpy, pytest and nbclient) and its pytest suite (`python/tests`,
//! the example notebook `python/examples/glint.ipynb` executed too) run
//! against this build's `glint`: renders, explain documents and images the
//! same bytes as the command line's, every bad input its exception, the GIL
//! released, Ctrl-C a `KeyboardInterrupt`. A real part ([`common::real_part`]):
//! without that environment the test says so, and fails under `CI=true`.

mod common;

use common::{python_in_venv, repo};
use std::process::Command;

#[test]
fn the_python_package_passes_its_pytest_suite() {
    let venv = ("GLINT_PYTHON_VENV", "target/python-venv");
    let install = "then pip install maturin numpy pytest nbclient nbformat ipykernel";
    let modules = "maturin, numpy, pytest, nbclient, ipykernel";
    let Some(python) = python_in_venv(venv, modules, install) else {
        return;
    };
    let bin = python.parent().expect("the venv's bin/");
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    // The dev profile (pyproject.toml names the wheel's): its dependencies
    // are the test build's, already built.
    let build = Command::new(bin.join("maturin"))
        .args([
            "develop",
            "--profile",
            "dev",
            "--manifest-path",
            "python/Cargo.toml",
        ])
        .current_dir(repo())
        .env("VIRTUAL_ENV", bin.parent().unwrap())
        .env("PATH", &path)
        .output()
        .expect("maturin runs");
    assert!(
        build.status.success(),
        "maturin develop failed:\n{}",
        String::from_utf8_lossy(&build.stderr)
    );
    let run = Command::new(&python)
        .args([
            "-m",
            "pytest",
            "python/tests",
            "-q",
            "-p",
            "no:cacheprovider",
        ])
        .current_dir(repo())
        .env("GLINT", env!("CARGO_BIN_EXE_glint"))
        .env("PATH", &path)
        .output()
        .expect("pytest runs");
    let out = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "pytest failed:\n{out}\n{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(out.contains(" passed") && !out.contains("skipped"), "{out}");
}
