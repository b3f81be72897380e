"""The package against the command line: the same scene and settings give
the same bytes, and every bad input its own exception."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import glint
from conftest import REPO, SCENES

try:
    import tomllib
except ImportError:  # Python < 3.11
    tomllib = None

SMALL = {"spp": 4, "resolution": (48, 40)}


def cli(glint_bin, *args, cwd=None):
    done = subprocess.run([glint_bin, *args], capture_output=True, text=True, cwd=cwd)
    assert done.returncode == 0, done.stderr
    return done.stdout


@pytest.mark.parametrize(
    "scene, settings, flags",
    [
        ("cornell-set1", SMALL, ["--spp", "4", "--resolution", "48x40"]),
        (
            "textured-spheres",
            {"spp": 2, "resolution": "40x32", "texture_filter": "ewa", "seed": 7},
            ["--spp", "2", "--resolution", "40x32", "--texture-filter", "ewa", "--seed", "7"],
        ),
        (
            "cornell-physical",
            {"spp": 3, "resolution": (32, 32), "light_samples": 2, "mis": False, "pixel_sampler": "random"},
            ["--spp", "3", "--resolution", "32x32", "--light-samples", "2", "--no-mis", "--sampler", "random"],
        ),
        (
            "environment",
            {"spp": 2, "resolution": (40, 24), "environment_sampling": "cosine", "max_depth": 2},
            ["--spp", "2", "--resolution", "40x24", "--environment-sampling", "cosine", "--max-depth", "2"],
        ),
    ],
)
def test_render_is_the_cli_render_bit_for_bit(glint_bin, tmp_path, scene, settings, flags):
    path = SCENES / f"{scene}.toml"
    out = tmp_path / "cli.pfm"
    cli(glint_bin, "render", str(path), *flags, "-o", str(out))
    image = glint.load(path, **settings).render()
    assert isinstance(image, np.ndarray) and isinstance(image, glint.Image)
    assert image.dtype == np.float32 and image.flags["C_CONTIGUOUS"]
    expected = glint.imread(out)
    assert image.shape == expected.shape
    assert np.array_equal(image.view(np.uint32), np.asarray(expected).view(np.uint32))
    # The same file written by the package is the same bytes.
    glint.imwrite(tmp_path / "py.pfm", image)
    assert (tmp_path / "py.pfm").read_bytes() == out.read_bytes()


def test_a_crop_is_the_whole_renders_pixels_and_an_aov_the_clis(glint_bin, tmp_path):
    scene = glint.load(SCENES / "cornell-set1.toml", **SMALL)
    whole = scene.render()
    window = scene.render(crop=(5, 7, 30, 21), threads=1)
    assert np.array_equal(window, whole[7:21, 5:30])
    out = tmp_path / "depth.pfm"
    cli(glint_bin, "render", str(SCENES / "cornell-set1.toml"), "--spp", "4", "--resolution", "48x40",
        "--aov", "depth", "-o", str(out))
    assert np.array_equal(scene.render(aov="depth"), glint.imread(out))


def test_explain_is_the_clis_json_byte_for_byte(glint_bin):
    path = SCENES / "physical-glossy.toml"
    flags = ["--spp", "4", "--light-samples", "2", "--resolution", "64x64"]
    for more, keywords in [([], {}), (["--all-samples"], {"all_samples": True}), (["--sample", "3"], {"sample": 3})]:
        expected = cli(glint_bin, "explain", str(path), *flags, "--pixel", "30,33", "--json", *more)
        scene = glint.load(path, spp=4, light_samples=2, resolution=(64, 64))
        assert scene.explain_json((30, 33), **keywords) == expected
        assert scene.explain((30, 33), **keywords) == json.loads(expected)


def test_a_scene_from_text_or_a_dict_renders_as_its_file():
    path = SCENES / "cornell-set1.toml"
    from_file = glint.load(path, **SMALL).render()
    from_text = glint.load_string(path.read_text(), base_dir=SCENES, **SMALL).render()
    assert np.array_equal(from_file, from_text)
    if tomllib is not None:
        tables = tomllib.loads(path.read_text())
        from_dict = glint.load_dict(tables, base_dir=SCENES, **SMALL).render()
        assert np.array_equal(from_file, from_dict)


def test_diff_measures_as_numpy_does():
    a = glint.load(SCENES / "cornell-set1.toml", **SMALL).render()
    b = glint.load(SCENES / "cornell-set1.toml", **SMALL, seed=3).render()
    d = glint.diff(a, b)
    rmse = np.sqrt(np.mean((a.astype(np.float64) - b.astype(np.float64)) ** 2))
    assert d["rmse"] == pytest.approx(rmse, rel=1e-9)
    assert d["max_difference"] == pytest.approx(float(np.abs(a - b).max()), rel=1e-6)
    assert d["means_test"] == pytest.approx(a.reshape(-1, 3).astype(np.float64).mean(axis=0).tolist(), rel=1e-9)
    assert glint.diff(a, a)["rmse"] == 0.0 and glint.diff(a, a)["flip"] == 0.0


def test_images_read_and_written_in_every_format_glint_writes(tmp_path):
    rng = np.random.default_rng(5)
    image = rng.random((9, 13, 3), dtype=np.float32)
    for ext in ["exr", "pfm"]:
        glint.imwrite(tmp_path / f"a.{ext}", image)
        back = glint.imread(tmp_path / f"a.{ext}")
        assert np.array_equal(back, image), ext
    glint.imwrite(tmp_path / "a.png", image)
    png = glint.imread(tmp_path / "a.png")
    assert "PNG" in png.format
    assert np.abs(png - image).max() < 0.01
    assert glint.Image(image)._repr_png_() == (tmp_path / "a.png").read_bytes()


def test_every_bad_input_has_its_exception(tmp_path):
    with pytest.raises(glint.SceneError) as bad_toml:
        glint.load_string("[camera]\nfov = = 3\n")
    assert isinstance(bad_toml.value, ValueError) and isinstance(bad_toml.value, glint.GlintError)
    assert (bad_toml.value.file, bad_toml.value.line) == ("<string>", 2)
    with pytest.raises(glint.SceneError) as wrong_type:
        glint.load_dict({"camera": {"fov": "wide"}})
    assert wrong_type.value.field == "camera.fov" and wrong_type.value.column is not None
    with pytest.raises(FileNotFoundError):
        glint.load(tmp_path / "missing.toml")
    with pytest.raises(FileNotFoundError):
        glint.imread(tmp_path / "missing.png")
    scene = glint.load(SCENES / "cornell-set1.toml", **SMALL)
    with pytest.raises(ValueError, match="unknown buffer"):
        scene.render(aov="colour")
    with pytest.raises(TypeError, match="unknown setting"):
        glint.load(SCENES / "cornell-set1.toml", spp_=4)
    with pytest.raises(ValueError, match="pixel_sampler"):
        glint.load(SCENES / "cornell-set1.toml", pixel_sampler="halton")
    with pytest.raises(ValueError, match="resolution"):
        glint.load(SCENES / "cornell-set1.toml", resolution="big")
    with pytest.raises(ValueError):
        scene.render(crop=(0, 0, 100, 100))
    with pytest.raises(ValueError):
        scene.explain((48, 0))
    with pytest.raises(TypeError, match="float32"):
        glint.imwrite(tmp_path / "a.pfm", np.zeros((4, 4, 3)))
    with pytest.raises(ValueError, match="shape"):
        glint.imwrite(tmp_path / "a.pfm", np.zeros((4, 4), dtype=np.float32))
    with pytest.raises(ValueError, match="size"):
        glint.diff(np.zeros((4, 4, 3), np.float32), np.zeros((4, 5, 3), np.float32))
    with pytest.raises(glint.GlintError):
        glint.imwrite(tmp_path / "a.bmp", np.zeros((4, 4, 3), np.float32))
    assert not (tmp_path / "a.pfm").exists() and not (tmp_path / "a.bmp").exists()


def test_the_gil_is_released_while_rendering():
    scene = glint.load(SCENES / "cornell-set1.toml", spp=16, resolution=(160, 120))
    ticks = []
    stop = threading.Event()

    def tick():
        while not stop.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    ticker = threading.Thread(target=tick)
    ticker.start()
    start = time.perf_counter()
    scene.render()
    took = time.perf_counter() - start
    stop.set()
    ticker.join()
    during = [t for t in ticks if start <= t <= start + took]
    # A thread that held the GIL for the whole render would leave no tick in it.
    assert len(during) >= 10, (took, len(during))


def test_progress_is_called_with_tiles_done_and_total():
    calls = []
    glint.load(SCENES / "cornell-set1.toml", spp=16, resolution=(160, 120)).render(
        progress=lambda done, total: calls.append((done, total)))
    assert calls and all(0 <= d <= t for d, t in calls if t)


def test_ctrl_c_raises_keyboard_interrupt_promptly():
    script = (
        "import glint, sys\n"
        f"scene = glint.load({str(SCENES / 'cornell-set1.toml')!r}, spp=4096, resolution=(512, 512))\n"
        "print('rendering', flush=True)\n"
        "scene.render()\n"
    )
    # As from a terminal: a shell's background job inherits SIGINT ignored,
    # and Python then installs no KeyboardInterrupt handler.
    default_sigint = lambda: signal.signal(signal.SIGINT, signal.SIG_DFL)
    child = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True, preexec_fn=default_sigint)
    assert child.stdout.readline().strip() == "rendering"
    time.sleep(0.5)
    sent = time.perf_counter()
    child.send_signal(signal.SIGINT)
    try:
        _, stderr = child.communicate(timeout=20)
    finally:
        child.kill()
    took = time.perf_counter() - sent
    assert "KeyboardInterrupt" in stderr, stderr
    assert child.returncode != 0
    # The render stops at each worker's next pixel; the process exits well within a second or two.
    assert took < 5.0, took


def test_the_installed_glint_command_is_the_program(glint_bin, tmp_path):
    command = os.path.join(os.path.dirname(sys.executable), "glint")
    assert os.path.exists(command), "pip install puts glint on PATH"
    scene = str(SCENES / "cornell-set1.toml")
    flags = ["--spp", "2", "--resolution", "32x24"]
    cli(glint_bin, "render", scene, *flags, "-o", str(tmp_path / "rust.png"))
    cli(command, "render", scene, *flags, "-o", str(tmp_path / "python.png"))
    assert (tmp_path / "python.png").read_bytes() == (tmp_path / "rust.png").read_bytes()
    bad = subprocess.run([command, "render", scene, "--spp", "zero"], capture_output=True, text=True)
    expected = subprocess.run([glint_bin, "render", scene, "--spp", "zero"], capture_output=True, text=True)
    assert (bad.returncode, bad.stderr) == (2, expected.stderr)
    assert len(bad.stderr.splitlines()) == 1


def test_grade_is_the_clis_document(glint_bin, tmp_path):
    scene = str(SCENES / "cornell-set1.toml")
    flags = ["--spp", "4", "--sampler", "random", "--light-samples", "4", "--light-sampler", "random"]
    good, bad = tmp_path / "good.pfm", tmp_path / "bad.pfm"
    cli(glint_bin, "render", scene, *flags, "--resolution", "64x64", "--seed", "5", "-o", str(good))
    image = glint.imread(good)
    glint.imwrite(bad, (image * np.float32(0.9)))
    stated = {"spp": 4, "pixel_sampler": "random", "light_samples": 4, "light_sampler": "random"}
    cache = tmp_path / "cache"
    done = subprocess.run(
        [glint_bin, "grade", scene, str(good), str(bad), *flags, "--format", "json", "--cache", str(cache),
         "--no-mistakes"],
        capture_output=True, text=True)
    assert done.returncode == 1, done.stderr
    report = glint.grade(scene, good, bad, cache=cache, **stated)
    assert report.to_dict() == json.loads(done.stdout)
    assert not report.passed
    assert [s["verdict"] for s in report.submissions] == ["pass", "fail"]
    # Each graded submission's heat map is glint grade --heatmap's picture.
    heatmap = tmp_path / "bad-heat.png"
    cli_heat = subprocess.run(
        [glint_bin, "grade", scene, str(bad), *flags, "--cache", str(cache), "--heatmap", str(heatmap)],
        capture_output=True, text=True)
    assert cli_heat.returncode == 1, cli_heat.stderr
    codes = report.heatmaps[1].astype(np.float32) / np.float32(255)
    linear = np.where(codes <= 0.04045, codes / np.float32(12.92), ((codes + np.float32(0.055)) / np.float32(1.055)) ** np.float32(2.4))
    assert report.heatmaps[1].dtype == np.uint8 and report.heatmaps[1].shape == image.shape
    assert np.allclose(linear, glint.imread(heatmap), rtol=1e-5, atol=1e-7)
    assert not np.array_equal(report.heatmaps[0], report.heatmaps[1])
    # An array is graded as its lossless file.
    assert glint.grade(scene, np.asarray(image), cache=cache, **stated).passed
    with pytest.raises(ValueError, match="sampler"):
        glint.grade(scene, good, pixel_sampler="halton")


def test_grade_a_scene_from_memory_keys_the_cache_by_its_text(glint_bin, tmp_path):
    path = SCENES / "cornell-set1.toml"
    flags = ["--spp", "4", "--sampler", "random", "--light-samples", "4", "--light-sampler", "random"]
    good, bad = tmp_path / "good.pfm", tmp_path / "bad.pfm"
    cli(glint_bin, "render", str(path), *flags, "--resolution", "48x40", "--seed", "5", "-o", str(good))
    glint.imwrite(bad, glint.imread(good) * np.float32(0.9))
    stated = {"spp": 4, "pixel_sampler": "random", "light_samples": 4, "light_sampler": "random"}
    by_file, by_text = tmp_path / "by-file", tmp_path / "by-text"

    def cached(folder):
        return {p.name: p.stat().st_mtime_ns for p in folder.iterdir()}

    from_file = glint.grade(path, good, bad, cache=by_file, **stated)
    # A Scene read from the file, nothing replaced, shares glint grade's cache.
    files = cached(by_file)
    again = glint.grade(glint.load(path), good, bad, cache=by_file, **stated)
    assert cached(by_file) == files
    assert again.to_dict() == from_file.to_dict()
    # The same text from memory grades alike, under its own name and key.
    text = path.read_text()
    from_text = glint.grade(glint.load_string(text, base_dir=SCENES), good, bad, cache=by_text, **stated)
    assert [s["verdict"] for s in from_text.submissions] == ["pass", "fail"]
    assert {s["scene"] for s in from_text.submissions} == {"<string>"}
    strip = lambda report: [{k: v for k, v in s.items() if k != "scene"} for s in report.submissions]
    assert strip(from_text) == strip(from_file)
    assert set(cached(by_text)).isdisjoint(files)
    # Graded again from equal text, the references are read, not rendered.
    texts = cached(by_text)
    glint.grade(glint.load_string(text, base_dir=SCENES), good, cache=by_text, **stated)
    assert cached(by_text) == texts
    # Other text, or a replaced setting, is another scene: references of its own.
    changed = text.replace("[camera]", "[camera]\n# a comment", 1)
    glint.grade(glint.load_string(changed, base_dir=SCENES), good, cache=by_text, **stated)
    glint.grade(glint.load_string(text, base_dir=SCENES, max_depth=2), good, cache=by_text, **stated)
    added = set(cached(by_text)) - set(texts)
    assert len(added) == 2 * len(texts), sorted(added)


def test_a_scene_from_memory_has_its_mistakes_named_edits_included(glint_bin, tmp_path):
    path = SCENES / "cornell-set1.toml"
    flags = ["--spp", "4", "--sampler", "random", "--light-samples", "4", "--light-sampler", "random"]
    stated = {"spp": 4, "pixel_sampler": "random", "light_samples": 4, "light_sampler": "random"}
    wrong = tmp_path / "no-ambient.png"
    cli(glint_bin, "render", str(path), *flags, "--resolution", "16x16", "--seed", "5", "--mistake", "no-ambient",
        "-o", str(wrong))
    # The text's settings replaced (depth) and the mistake an edit of the text;
    # 16 × 16 pixels, as every mistake is rendered (in the dev profile).
    scene = glint.load_string(path.read_text(), base_dir=SCENES, max_depth=2)
    report = glint.grade(scene, wrong, cache=tmp_path / "cache", mistakes=True, **stated)
    [graded] = report.submissions
    assert graded["verdict"] == "fail"
    first = graded["likely_mistakes"][0]
    assert (first["id"], first["consistent"]) == ("no-ambient", True), graded["likely_mistakes"][:3]


def test_explain_against_is_the_clis_comparison(glint_bin, tmp_path):
    path = SCENES / "cornell-set1.toml"
    flags = ["--spp", "4", "--resolution", "48x40"]
    scene = glint.load(path, spp=4, resolution=(48, 40))
    student = scene.explain((20, 30))
    student["film"]["srgb8"] = [0, 0, 0]
    student_file = tmp_path / "student.json"
    student_file.write_text(json.dumps(student))
    done = subprocess.run(
        [glint_bin, "explain", str(path), *flags, "--pixel", "20,30", "--against", str(student_file), "--json"],
        capture_output=True, text=True)
    assert done.returncode == 1, done.stderr
    expected = json.loads(done.stdout)
    assert scene.explain_against((20, 30), student) == expected
    assert scene.explain_against((20, 30), student_file) == expected
    with pytest.raises(ValueError, match="student"):
        scene.explain_against((20, 30), "{ not json")


def test_a_class_is_graded_as_the_cli_grades_it(glint_bin, tmp_path):
    import shutil

    scenes = tmp_path / "scenes"
    scenes.mkdir()
    shutil.copy(SCENES / "cornell-set1.toml", scenes / "set1.toml")
    flags = ["--spp", "4", "--sampler", "random", "--light-samples", "4", "--light-sampler", "random"]
    for k, student in enumerate(["ada", "bo"]):
        (tmp_path / "class" / student).mkdir(parents=True)
        cli(glint_bin, "render", str(scenes / "set1.toml"), *flags, "--resolution", "48x48",
            "--seed", str(k + 1), "-o", str(tmp_path / "class" / student / "set1.png"))
    cache = tmp_path / "cache"
    done = subprocess.run(
        [glint_bin, "grade", "--class", str(tmp_path / "class"), "--scenes", str(scenes), *flags,
         "--format", "json", "--cache", str(cache)],
        capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    report = glint.grade_class(tmp_path / "class", scenes=scenes, cache=cache, spp=4, pixel_sampler="random",
                               light_samples=4, light_sampler="random")
    assert report.to_dict() == json.loads(done.stdout)
    assert report.passed and len(report.submissions) == 2
