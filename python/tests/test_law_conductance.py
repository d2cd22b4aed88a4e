"""ContactLaw's interface conductance, as the C ABI's (the same runtime code,
strata_runtime::interface::conductance_curve): h_c(g) is the solved values at the samples,
PCHIP (Fritsch-Butland slopes, three-point end rule) between them and h1*sqrt(delta/delta1)
in the first interval; h_c(p) is h_c at the separation where p(g) = p. Checked against
scipy's PchipInterpolator (an independent PCHIP) and the CLI: `csv()` is `strata law`'s CSV
with its `conductance` column, byte for byte.
"""

import os

import numpy as np
import pytest

import strata


def scene_text(root):
    return f"""
[stack]
file = "{root / 'tables/stacks/half-space-steel-conducting.toml'}"
[surface]
periodic = true
[surface.generate]
size = 1e-3
grid = 64
fractal_dimension = 2.4
k_min = 2
k_max = 10
rms = 3.4e-6
seed = 5
[model]
kind = "independent"
[conductance]
kind = "thermal"
[counterface]
conduction = "perfect"
[load]
approach = {{ from = 1e-6, to = 6e-6, steps = 3 }}
"""


def test_contact_law_conductance_like_the_c_abi(root, cli, tmp_path):
    (tmp_path / "scene.toml").write_text(scene_text(root))
    cli("law", tmp_path / "scene.toml", "--out", tmp_path / "law.csv", "--samples", "24")
    law = strata.Scene.from_file(str(tmp_path / "scene.toml")).law(samples=24)
    assert law.conductance_kind == "thermal"
    # the CLI's CSV, its conductance column included
    assert law.csv() == (tmp_path / "law.csv").read_text()
    assert law.csv().splitlines()[0].endswith(",conductance")
    s = law.samples
    g, h, p = s["gap"], s["conductance"], s["mean_pressure"]
    assert len(h) == 24 and h[0] == 0.0 and np.all(np.diff(h) >= 0)
    # at the samples: the solved values exactly, by gap and by pressure
    assert np.array_equal(law.conductance(g), h)
    assert np.array_equal(law.conductance_at_pressure(p[1:]), h[1:])
    assert law.conductance(law.first_contact_gap + 1e-7) == 0.0
    # between samples: an independent PCHIP (scipy) on ascending separations, beyond
    # the first interval (there h_c = h1 sqrt(delta/delta1), one spot)
    try:
        from scipy.interpolate import PchipInterpolator
    except ImportError:
        if os.environ.get("STRATA_REQUIRE_TOOLS") == "1":
            pytest.fail("scipy is not installed (STRATA_REQUIRE_TOOLS=1)")
        pytest.skip("scipy is not installed: *** this test did NOT run")
    pchip = PchipInterpolator(g[::-1], h[::-1])
    mid = 0.5 * (g[1:-1] + g[2:])
    np.testing.assert_allclose(law.conductance(mid), pchip(mid), rtol=1e-12, atol=0)
    g0, g1 = g[0], g[1]
    x = g0 - 0.3 * (g0 - g1)
    assert law.conductance(x) == pytest.approx(h[1] * np.sqrt(0.3), rel=1e-14)
    # h_c(p) between samples: h_c at the separation where p(g) = p (bisection)
    back = law.conductance_at_pressure(law.pressure(mid))
    np.testing.assert_allclose(back, law.conductance(mid), rtol=1e-10)
    with pytest.raises(strata.LawError, match="gap"):
        law.conductance(law.min_gap - 1e-7)
    with pytest.raises(strata.LawError, match="pressure"):
        law.conductance_at_pressure(2 * p[-1])


def test_a_law_without_conductance_says_so(root, tmp_path):
    text = scene_text(root).replace('[conductance]\nkind = "thermal"\n[counterface]\nconduction = "perfect"\n', "")
    (tmp_path / "scene.toml").write_text(text)
    law = strata.Scene.from_file(str(tmp_path / "scene.toml")).law(samples=8)
    assert law.conductance_kind is None
    assert "conductance" not in law.samples
    with pytest.raises(strata.LawError, match=r"\[conductance\]"):
        law.conductance(law.first_contact_gap)
