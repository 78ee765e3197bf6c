"""The compiled CasADi functions' cache: the same values as CasADi's virtual machine, a
stale build rebuilt and never loaded, and the Python path (one warning line) without a
compiler or when the build fails."""

from __future__ import annotations

import shutil
from pathlib import Path

import casadi as ca
import numpy as np
import pytest

from ridempc.mpc import codegen
from ridempc.mpc.buffered import BufferedFunction
from ridempc.mpc.codegen import COMPILER_ENV, compiled, library_path

needs_gcc = pytest.mark.skipif(codegen._compiler() is None, reason="no C compiler here")


def _model(gain: float) -> ca.Function:
    """A small model, ``gain`` telling one version from another."""
    x, u = ca.SX.sym("x", 3), ca.SX.sym("u", 2)
    rates = ca.vertcat(x[1], gain * ca.sin(x[0]) + u[0] * x[2], u[1] - x[2] ** 2)
    jacobians = ca.Function("toy_jacobians", [x, u], [rates, ca.jacobian(rates, x)])
    return jacobians.map(4)


def _values(function: ca.Function) -> list[np.ndarray]:
    rng = np.random.default_rng(0)
    x, u = rng.normal(size=(3, 4)), rng.normal(size=(2, 4))
    return [np.asarray(ca.DM(out)) for out in function(x, u)]


@pytest.fixture(autouse=True)
def _fresh_warnings() -> None:
    codegen._warn.cache_clear()  # one warning per process: each test sees its own


@needs_gcc
def test_a_compiled_function_is_bitwise_the_virtual_machines(tmp_path: Path) -> None:
    function = _model(9.81)
    built = compiled(function, tmp_path)
    assert built.is_a("External")
    for mine, theirs in zip(_values(built), _values(function), strict=True):
        assert np.array_equal(mine, theirs)
    library = next(tmp_path.glob("*.so"))
    stamp = library.stat().st_mtime_ns
    compiled(function, tmp_path)  # from the cache: not built again
    assert library.stat().st_mtime_ns == stamp and len(list(tmp_path.glob("*.so"))) == 1


@needs_gcc
def test_a_stale_build_is_rebuilt_not_loaded(tmp_path: Path) -> None:
    old, new = _model(9.81), _model(3.71)
    compiled(old, tmp_path)
    (old_library,) = tmp_path.glob("*.so")
    compiler = codegen._compiler()
    assert compiler is not None
    key = codegen._key(new, compiler)
    assert key != codegen._key(old, compiler)  # another version, another key
    # a build of the old version where the new one's would be (its key not inside)
    target = library_path(new, tmp_path, key)
    shutil.copyfile(old_library, target)
    assert not codegen._holds_key(target, key)
    built = compiled(new, tmp_path)
    assert codegen._holds_key(target, key)  # rebuilt in place
    for mine, theirs in zip(_values(built), _values(new), strict=True):
        assert np.array_equal(mine, theirs)
    assert not np.array_equal(_values(built)[0], _values(old)[0])


def test_without_a_compiler_the_python_path_with_one_warning(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setenv(COMPILER_ENV, "")
    function = _model(9.81)
    assert compiled(function, tmp_path) is function
    assert compiled(_model(1.0), tmp_path) is not None  # a second function: no second line
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("ridempc: warning: no C compiler found")
    assert not list(tmp_path.iterdir())


def test_a_failed_build_takes_the_python_path_with_one_warning(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.setenv(COMPILER_ENV, "false")  # a "compiler" that always fails
    function = _model(9.81)
    assert compiled(function, tmp_path) is function
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "building map4_toy_jacobians" in err and "failed" in err
    assert not list(tmp_path.glob("*.so"))


def test_a_buffered_function_gives_casadis_dense_outputs() -> None:
    function = _model(9.81)
    buffered = BufferedFunction(function)
    rng = np.random.default_rng(4)
    for _ in range(3):
        x, u = rng.normal(size=(3, 4)), rng.normal(size=(2, 4))
        for mine, theirs in zip(buffered(x, u), function(x, u), strict=True):
            assert np.array_equal(mine, np.asarray(ca.DM(theirs)))
    sparse = ca.Function("sparse", [ca.SX.sym("s", ca.Sparsity.diag(3))], [ca.SX(1, 1)])
    with pytest.raises(ValueError, match="input 0 of sparse is sparse"):
        BufferedFunction(sparse)
