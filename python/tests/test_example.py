"""The example under examples/ runs: the README's walk-through in Python."""

import subprocess
import sys

from conftest import REPO


def test_the_walkthrough_runs_and_says_what_it_found(tmp_path):
    script = REPO / "examples" / "python_walkthrough.py"
    done = subprocess.run([sys.executable, str(script), str(tmp_path)], capture_output=True,
                          text=True, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    out = done.stdout
    assert "peak |x| = 41.69 mm at ω = 6.22 rad/s" in out, out
    assert "power_law: K = " in out and "best by regime:" in out
    assert "effects ['cubic_stiffness']" in out
    assert (tmp_path / "power_law_fit.svg").is_file()
