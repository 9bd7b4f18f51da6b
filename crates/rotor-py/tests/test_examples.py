"""The Python examples run as written (examples/python/), in a scratch directory."""

import os
import subprocess
import sys

import rotorbench
from conftest import REPO

EXAMPLES = REPO / "examples" / "python"


def run(script, *args, cwd):
    env = dict(os.environ, MPLBACKEND="Agg")
    p = subprocess.run([sys.executable, str(EXAMPLES / script), *args], cwd=cwd, env=env,
                       capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    return p.stdout


def test_figure4_writes_the_picture(tmp_path):
    out = run("figure4.py", cwd=tmp_path)
    png = tmp_path / "figure4.png"
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # The steady state printed is the package's answer for the scene.
    st = rotorbench.steady(u=1.5)
    assert out.startswith(
        f"figure4.png: period {st['period']:.6f} s, omega_l max {st['omega_l_max']:.6f} rad/s"
    )


def test_grade_scipy_grades_and_compares(tmp_path):
    out = run("grade_scipy.py", cwd=tmp_path)
    assert "t1-u1.5-rest: solve_ivp LSODA, tanh smoothing eps = 0.0001 rad/s" in out
    assert "loose gate: " in out and "strict gate: " in out
    # The smoothed model never sticks: its stick intervals are graded and fail.
    assert any(line.split()[:1] == ["stick_lower"] and "fails" in line for line in out.splitlines())
    assert out.rstrip().endswith("strict gate PASSED")


def test_the_readme_python_block_runs_as_written():
    text = (REPO / "README.md").read_text()
    section = text[text.index("## Python: `import rotorbench`"):]
    block = section[section.index("```python\n") + len("```python\n"):]
    block = block[: block.index("```")]
    scope = {}
    exec(compile(block, "README.md", "exec"), scope)
    # What its comments promise.
    assert scope["r"]["omega_l"].dtype.name == "float64"
    assert len(scope["cycles"]) == 50 and scope["diagram"]["points"]
    verdict = rotorbench.check("t1-u1.5-rest", *(scope["m"][c] for c in ("t", "alpha", "omega_u", "omega_l")))
    assert verdict["passed"]


def test_redraw_bench_draws_a_published_figure_from_its_csv(tmp_path):
    src = REPO / "reports" / "bench" / "bench-t1-u1.5-rest.csv"
    rows = src.read_text().splitlines()[1:]
    out = run("redraw_bench.py", str(src), "w.png", cwd=tmp_path)
    assert (tmp_path / "w.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    runners = {r.split(",")[0] for r in rows}
    assert out.strip() == f"w.png: {len(runners)} runners, {len(rows)} points"
