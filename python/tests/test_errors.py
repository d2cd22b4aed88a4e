"""Every error path raises a Python exception (a strata.StrataError subclass, or
FileNotFoundError for a missing file) carrying the library's message: no abort, no
panic (pyo3's PanicException is a BaseException, not an Exception: it would escape
`pytest.raises(Exception)` and fail these tests)."""

import subprocess
import sys
import textwrap

import numpy as np
import pytest

import strata

GOOD = dict(size=1e-3, periodic=True)


def heights(n=32, seed=3):
    g = strata.Surface.generate(size=1e-3, grid=n, fractal_dimension=2.4, k_min=2, k_max=8, rms=1e-6, seed=seed)
    return g.heights


def test_hierarchy():
    for cls in (strata.StackError, strata.TableError, strata.SurfaceError, strata.SceneError,
                strata.SolveError, strata.LawError):
        assert issubclass(cls, strata.StrataError)
    assert issubclass(strata.StrataError, ValueError)


@pytest.mark.parametrize("dtype", [np.int64, np.int32, np.complex128, object, np.bool_])
def test_bad_dtype(dtype):
    z = heights().astype(dtype)
    with pytest.raises(strata.SurfaceError, match="dtype"):
        strata.Surface(z, **GOOD)


def test_float32_is_widened_exactly():
    z = heights().astype(np.float32)
    s = strata.Surface(z, **GOOD)
    np.testing.assert_array_equal(s.heights, z.astype(np.float64))


def test_string_array_and_list_refused():
    with pytest.raises(strata.SurfaceError, match="dtype"):
        strata.Surface(np.array([["a", "b", "c"]] * 3), **GOOD)
    with pytest.raises(strata.SurfaceError, match="numpy array"):
        strata.Surface([[0.0] * 4] * 4, **GOOD)


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_height(bad):
    z = heights()
    z[5, 7] = bad
    with pytest.raises(strata.SurfaceError, match=r"row 5, column 7"):
        strata.Surface(z, **GOOD)
    # and repaired on request, as in a scene (repair = "median")
    s = strata.Surface(z, repair="median", **GOOD)
    assert np.isfinite(s.heights).all()


def test_masked_points_are_missing_values():
    # the values under a numpy mask were once taken as heights
    z = heights()
    m = np.ma.masked_array(z.copy(), mask=np.zeros_like(z, dtype=bool))
    m[6, 2] = np.ma.masked
    m.data[6, 2] = 1.0  # a wild value under the mask
    with pytest.raises(strata.SurfaceError, match=r"row 6, column 2"):
        strata.Surface(m, **GOOD)
    s = strata.Surface(m, repair="median", **GOOD)
    assert abs(s.heights[6, 2]) < 1e-4
    # unmasked: the same as the plain array
    plain = np.ma.masked_array(z, mask=False)
    assert np.array_equal(strata.Surface(plain, **GOOD).heights, strata.Surface(z, **GOOD).heights)


def test_huge_array_refused_under_the_memory_limit(monkeypatch):
    # Surface(array) once ignored the limit (a 16384² view aborted the interpreter)
    monkeypatch.setenv("STRATA_MEMORY_LIMIT", "64M")
    view = np.broadcast_to(np.float64(1e-6), (16384, 16384))
    with pytest.raises(strata.SurfaceError, match=r"16384×16384.*limit"):
        strata.Surface(view, **GOOD)
    with pytest.raises(strata.SurfaceError, match=r"limit"):
        strata.Surface.generate(1e-3, 8192, 2.4, 2, 10, 1e-6)


def test_counts_and_lengths_are_named():
    # negative ints once raised OverflowError without the parameter's name, and
    # bools were taken as numbers (size=True gave a 1 m sample)
    with pytest.raises(strata.SurfaceError, match=r"grid = -5"):
        strata.Surface.generate(1e-3, -5, 2.4, 2, 10, 1e-6)
    with pytest.raises(strata.SurfaceError, match=r"seed = -1"):
        strata.Surface.generate(1e-3, 64, 2.4, 2, 10, 1e-6, seed=-1)
    with pytest.raises(strata.SurfaceError, match=r"grid: .*bool"):
        strata.Surface.generate(1e-3, True, 2.4, 2, 10, 1e-6)
    with pytest.raises(strata.SurfaceError, match=r"size: .*bool"):
        strata.Surface(heights(), size=True)
    assert isinstance(strata.SurfaceError("x"), ValueError)
    # the default seed is 1, as before
    a = strata.Surface.generate(1e-3, 32, 2.4, 2, 10, 1e-6)
    b = strata.Surface.generate(1e-3, 32, 2.4, 2, 10, 1e-6, seed=1)
    assert np.array_equal(a.heights, b.heights)


def test_table_g_names_r_and_a():
    # Table.g(1e-4, 1e-5) once said "r ... must be >= a = 0.00001" (a and r swapped)
    import pathlib
    root = pathlib.Path(__file__).resolve().parents[2]
    t = strata.Table.load(str(root / "tables" / "paper-two-layer.strata"))
    with pytest.raises(strata.TableError) as e:
        t.g(1e-4, 1e-5)
    m = str(e.value)
    assert "at least the contact radius a" in m and "= 0.00001 is outside the table range [0.0001" in m, m


def test_spike_refused_with_its_index():
    z = heights()
    z[4, 9] = 1.0  # 1 m on a micrometre surface
    with pytest.raises(strata.SurfaceError, match=r"row 4, column 9.*spike"):
        strata.Surface(z, **GOOD)


@pytest.mark.parametrize("shape", [(1024,), (4, 4, 4), (2, 10), (10, 2), (0, 0)])
def test_wrong_shape(shape):
    z = np.zeros(shape)
    with pytest.raises(strata.SurfaceError):
        strata.Surface(z, size=1e-3)


def test_non_contiguous_and_fortran_order_are_read_by_index():
    z = heights(64)
    s1 = strata.Surface(z[::2, ::2], **GOOD)
    s2 = strata.Surface(np.asfortranarray(z), **GOOD)
    np.testing.assert_array_equal(s1.heights, z[::2, ::2])
    np.testing.assert_array_equal(s2.heights, z)


@pytest.mark.parametrize("kw,field", [
    (dict(), "size"),
    (dict(size=-1e-3), "size"),
    (dict(size=np.nan), "size"),
    (dict(pixel_size=(0.0, 1e-6)), "pixel_size"),
    (dict(size=1e-3, pixel_size=(1e-6, 1e-6)), "not both"),
    (dict(size="big"), "size"),
])
def test_bad_sizes(kw, field):
    with pytest.raises(strata.SurfaceError, match=field):
        strata.Surface(heights(), **kw)


def test_bad_generate():
    with pytest.raises(strata.SurfaceError, match="k_max"):
        strata.Surface.generate(size=1e-3, grid=32, fractal_dimension=2.4, k_min=2, k_max=100, rms=1e-6)
    with pytest.raises(strata.SurfaceError, match="rms"):
        strata.Surface.generate(size=1e-3, grid=32, fractal_dimension=2.4, k_min=2, k_max=8, rms=-1.0)


def test_missing_files(tmp_path):
    missing = tmp_path / "nope"
    with pytest.raises(FileNotFoundError, match="nope.npy"):
        strata.Surface.read(str(missing) + ".npy", size=1e-3)
    with pytest.raises(FileNotFoundError, match="nope.toml"):
        strata.Stack.from_file(str(missing) + ".toml")
    with pytest.raises(FileNotFoundError, match="nope.strata"):
        strata.Table.load(str(missing) + ".strata")
    with pytest.raises(FileNotFoundError, match="nope.toml"):
        strata.solve(str(missing) + ".toml")


def test_scene_naming_a_missing_surface_file(tmp_path, root):
    (tmp_path / "s.toml").write_text(textwrap.dedent(f"""
        [stack]
        file = "{root / 'tables/stacks/half-space-steel.toml'}"
        [surface]
        file = "gone.npy"
        size = 1e-3
        [model]
        kind = "independent"
        [load]
        separations = [1e-6]
    """))
    with pytest.raises(strata.SceneError, match=r"surface.file.*gone.npy"):
        strata.Scene.from_file(tmp_path / "s.toml")


def test_bad_npy_files(tmp_path):
    p = tmp_path / "ints.npy"
    np.save(p, np.zeros((8, 8), dtype=np.int32))
    with pytest.raises(strata.SurfaceError, match="ints.npy"):
        strata.Surface.read(p, size=1e-3)
    q = tmp_path / "garbage.npy"
    q.write_bytes(b"\x93NUMPY garbage")
    with pytest.raises(strata.SurfaceError, match="garbage.npy"):
        strata.Surface.read(q, size=1e-3)
    r = tmp_path / "nan.npy"
    z = heights()
    z[2, 3] = np.nan
    np.save(r, z)
    with pytest.raises(strata.SurfaceError, match=r"nan.npy.*row 2, column 3"):
        strata.Surface.read(r, size=1e-3)


def test_bad_toml_fields(tmp_path, root):
    scene = (root / "scenes" / "paper-E2E1-5-interacting.toml").read_text()
    bad = scene.replace("steps = 20", "steps = 0")
    p = tmp_path / "bad.toml"
    p.write_text(bad.replace("../tables", str(root / "tables")))
    with pytest.raises(strata.SceneError, match=r"bad.toml.*load.approach.steps"):
        strata.Scene.from_file(p)
    p.write_text(scene.replace("../tables", str(root / "tables")).replace('kind = "interacting"', 'kind = "magic"'))
    with pytest.raises(strata.SceneError, match=r"model.kind.*magic"):
        strata.Scene.from_file(p)
    p.write_text(scene.replace("../tables", str(root / "tables")).replace("[load]", "[load]\nbogus = 1"))
    with pytest.raises(strata.SceneError, match="bogus"):
        strata.Scene.from_file(p)
    with pytest.raises(strata.SceneError, match="TOML"):
        strata.Scene.from_toml("[stack\n")


@pytest.mark.parametrize("text,field", [
    ("[[layer]]\nthickness = -1e-6\nyoung = 4e9\npoisson = 0.15\n[base]\nkind = \"rigid\"\n", "thickness"),
    ("[[layer]]\nthickness = 1e-6\nyoung = 4e9\npoisson = 0.7\n[base]\nkind = \"rigid\"\n", "poisson"),
    ("[base]\nkind = \"rigid\"\n", "rigid"),
    ("[[layer]]\nthickness = 1e-6\nyoung = \"x\"\npoisson = 0.1\n[base]\nkind = \"rigid\"\n", "young"),
])
def test_bad_stack_toml(text, field):
    with pytest.raises(strata.StackError, match=field):
        strata.Stack.from_toml(text)


def test_bad_stack_lists():
    with pytest.raises(strata.StackError, match=r"layer 1.*young|young.*layer 1"):
        strata.Stack([(1e-4, -4e9, 0.15)])
    with pytest.raises(strata.StackError, match=r"layers\[0\].young"):
        strata.Stack([(1e-4, "hard", 0.15)])
    with pytest.raises(strata.StackError, match="expected 3 numbers"):
        strata.Stack([(1e-4, 4e9)])
    with pytest.raises(strata.StackError, match="unknown key `E`"):
        strata.Stack([{"thickness": 1e-4, "E": 4e9, "poisson": 0.1}])
    with pytest.raises(strata.StackError, match="rigid"):
        strata.Stack([], base="rigid")
    with pytest.raises(strata.StackError, match="granite"):
        strata.Stack([(1e-4, 4e9, 0.15)], base="granite")


def test_bad_in_memory_scene(root):
    stack = strata.Stack.half_space(210e9, 0.3)
    surf = strata.Surface(heights(), size=1e-3, periodic=False)
    with pytest.raises(strata.SceneError, match="model.images"):
        strata.Scene(stack, surf, model="interacting", images="periodic", load={"separations": [1e-6]})
    with pytest.raises(strata.SceneError, match=r"load.mean_pressures\[1\]"):
        strata.Scene(stack, surf, model="independent", load={"mean_pressures": [1e5, -1.0]})
    with pytest.raises(strata.SceneError, match="missing field `load`"):
        strata.Scene(stack, surf, model="independent")
    with pytest.raises(strata.SceneError, match="finite"):
        strata.Scene(stack, surf, model="independent", load={"separations": [float("nan")]})
    with pytest.raises(strata.SurfaceError, match="Surface or a SurfaceTopography"):
        strata.Scene(stack, np.zeros((8, 8)), model="independent", load={"separations": [1e-6]})
    scene = strata.Scene(stack, surf, model="independent", load={"separations": [1.0]})
    with pytest.raises(strata.SolveError, match=r"load.separations\[0\]"):
        scene.solve()
    with pytest.raises(strata.SceneError, match="bem"):
        scene.solve(maps="all")


def test_bad_lookups(root):
    table = strata.Table.load(root / "tables" / "paper-two-layer.strata")
    lo, hi = table.law().a_range
    with pytest.raises(strata.TableError):
        table.chi(hi * 10)
    with pytest.raises(strata.TableError, match="dtype"):
        table.chi(np.array([1, 2, 3]))
    with pytest.raises(strata.TableError):
        table.law(strata.Stack.half_space(210e9, 0.3))
    with pytest.raises(strata.StackError, match="NaN"):
        table.stack.compliance(np.nan)


def test_bad_indent(root):
    stack = strata.Stack.from_file(root / "tables" / "stacks" / "paper-two-layer.toml")
    with pytest.raises(strata.SolveError, match="radius"):
        strata.indent(stack, -1.0, [1e-7])
    with pytest.raises(strata.SolveError, match="deltas"):
        strata.indent(stack, 1e-4, [1e-7, -1e-7])
    with pytest.raises(strata.SolveError, match="model"):
        strata.indent(stack, 1e-4, [1e-7], model="exact")


def test_bad_law_queries(root):
    law = strata.Scene.from_file(root / "scenes" / "paper-E2E1-5-independent.toml").law(samples=20)
    with pytest.raises(strata.LawError):
        law.pressure(np.nan)
    with pytest.raises(strata.LawError, match="samples"):
        strata.Scene.from_file(root / "scenes" / "paper-E2E1-5-independent.toml").law(samples=1)


def test_no_panic_text_in_a_subprocess(tmp_path):
    """A bad call in a fresh interpreter: a clean traceback, exit 1, no Rust panic text."""
    code = "import numpy as np, strata; strata.Surface(np.full((8, 8), np.nan), size=1e-3)"
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert p.returncode == 1
    assert "strata.SurfaceError" in p.stderr or "SurfaceError" in p.stderr
    assert "panicked" not in p.stderr and "RUST_BACKTRACE" not in p.stderr
