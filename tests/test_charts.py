"""Figures: written atomically, byte-reproducible, bad paths refused before any work."""

from __future__ import annotations

import subprocess
import sys

import pytest
from lindstedt.charts import check_plot_path, mixing_figure
from lindstedt.errors import InputError


def test_mixing_figure_is_a_reproducible_png(tmp_path):
    a, b = tmp_path / "a.png", tmp_path / "b.png"
    mixing_figure(0.1, 10.0, [(0.3, 1.3), (0.3, 1.7)], a)
    mixing_figure(0.1, 10.0, [(0.3, 1.3), (0.3, 1.7)], b)
    assert a.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert a.read_bytes() == b.read_bytes()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.png", "b.png"]  # no temporaries


@pytest.mark.parametrize("bad", ["out.jpg", "/no/such/folder/x.png", "noext"])
def test_bad_plot_paths(bad):
    with pytest.raises(InputError):
        check_plot_path(bad)


def test_cli_refuses_bad_plot_path_before_computing(tmp_path):
    run = subprocess.run([sys.executable, "-m", "lindstedt", "response", "--eps", "0.1",
                          "--force", "0.3", "--Q", "20", "--plot", str(tmp_path / "x.gif")],
                         capture_output=True, text=True, check=False)
    assert run.returncode == 2 and run.stdout == "" and "--plot" in run.stderr
    assert list(tmp_path.iterdir()) == []
