"""The documented Python example (docs/embedding.md, "In Python") runs as written (from the
repository root)."""

import os
import re

import pytest

import strata


def test_readme_example_runs(root, monkeypatch):
    pytest.importorskip("matplotlib") if os.environ.get("STRATA_REQUIRE_TOOLS") != "1" else None
    import matplotlib
    matplotlib.use("Agg")
    text = (root / "docs" / "embedding.md").read_text(encoding="utf-8")
    section = text[text.index("## In Python"):]
    block = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    monkeypatch.chdir(root)
    env = {}
    exec(compile(block, "docs/embedding.md", "exec"), env)
    assert isinstance(env["curve"], strata.Curve) and len(env["curve"]) == 20
    assert env["law"].pressure(env["law"].first_contact_gap - 1e-6) > 0
