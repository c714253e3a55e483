"""The README's Python quick start runs as written: each ```python block, in order, in one fresh interpreter, in a
folder that holds the repository's campaigns as the repository's root does (its results go there, not into the
checkout)."""

import os
import re
import subprocess
import sys

import pytest

from .conftest import REPO

pytestmark = pytest.mark.slow  # flies 64 flights and one recorded flight: ~1 min with their compilation


def test_the_python_quick_start_runs(tmp_path):
    blocks = re.findall(r"```python\n(.*?)```", (REPO / "README.md").read_text(), re.S)
    assert blocks, "the README shows no Python"
    (tmp_path / "campaigns").symlink_to(REPO / "campaigns")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(sys.path)}
    done = subprocess.run([sys.executable, "-c", "\n".join(blocks)], cwd=tmp_path, env=env, capture_output=True,
                          text=True, timeout=1200)  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    assert "Campaign 'lynx_nominal'" in done.stdout and (tmp_path / "results" / "quickstart.h5").is_file()
