"""The vendored Lynx DATCOM table: loaded as a Table, matches scipy, SOURCE.md samples, clear errors."""

from __future__ import annotations

import jax
import numpy as np
import pytest
import scipy.io
from scipy.interpolate import RegularGridInterpolator

from rocketmc.aero.datcom import DATCOM_AXES, DATCOM_COEFFS, LYNX_DATCOM, DatcomFileError, load_datcom_mat
from rocketmc.math.table import interpolate


@pytest.fixture(scope="module")
def lynx():
    return load_datcom_mat(LYNX_DATCOM)


@pytest.fixture(scope="module")
def lynx_mat():
    return scipy.io.loadmat(LYNX_DATCOM, squeeze_me=True, struct_as_record=False)


def test_layout(lynx):
    assert lynx.axis_names == DATCOM_AXES
    assert lynx.output_names == DATCOM_COEFFS and len(DATCOM_COEFFS) == 26
    assert lynx.values.shape == (19, 20, 7, 11, 26)


def test_matches_scipy_on_random_points(lynx, lynx_mat):
    state, coeffs = lynx_mat["State"], lynx_mat["Coeffs"]
    grid = (state.Alphas, state.Machs, state.Betas, state.Altitudes)  # deg, -, deg, m
    reference = RegularGridInterpolator(grid, np.stack([getattr(coeffs, n) for n in DATCOM_COEFFS], -1))
    rng = np.random.default_rng(2021)
    points = np.stack([rng.uniform(g[0], g[-1], 500) for g in grid], axis=-1)
    values, out_of_range = jax.vmap(interpolate, in_axes=(None, 0))(
        lynx, (np.deg2rad(points[:, 0]), points[:, 1], np.deg2rad(points[:, 2]), points[:, 3])
    )
    # Same multilinear formula; the deg->rad conversion shifts the cell fractions by ~1 ulp, and
    # |coefficients| <= ~1e3 (CMQ, CLNR), so the differences are ~1e-13: 1e-12 is the project's acceptance.
    np.testing.assert_allclose(values, reference(points), rtol=1e-12, atol=1e-12)
    assert not np.any(out_of_range)


# SOURCE.md sample values at alpha = beta = 0, altitude 109 m: (Mach, coefficient, printed value,
# printed decimals). Each is compared after rounding to the digits SOURCE.md prints.
SAMPLES = [
    (0.3, "CA", 0.362, 3),
    (0.3, "CNA", 10.10, 2),
    (0.3, "CMA", -23.1, 1),
    (0.3, "CMQ", -726.0, 0),
    (0.3, "CLLP", -11.1, 1),
    (0.85, "CA", 0.331, 3),
    (1.0, "CA", 0.477, 3),
]


@pytest.mark.parametrize(("mach", "name", "printed", "decimals"), SAMPLES)
def test_source_md_samples(lynx, mach, name, printed, decimals):
    values, out_of_range = interpolate(lynx, (0.0, mach, 0.0, 109.0))
    assert not out_of_range
    assert round(float(values[DATCOM_COEFFS.index(name)]), decimals) == printed


def test_missing_file(tmp_path):
    path = tmp_path / "nope.mat"
    with pytest.raises(DatcomFileError, match="nope.mat.*not found"):
        load_datcom_mat(path)
    assert issubclass(DatcomFileError, ValueError)


def test_not_a_mat_file(tmp_path):
    path = tmp_path / "garbage.mat"
    path.write_bytes(b"this is not a MATLAB file\n" * 10)
    with pytest.raises(DatcomFileError, match="garbage.mat"):
        load_datcom_mat(path)


def test_missing_field(tmp_path, lynx_mat):
    state, coeffs = lynx_mat["State"], lynx_mat["Coeffs"]
    path = tmp_path / "no_cmq.mat"
    fields = {n: getattr(coeffs, n) for n in DATCOM_COEFFS if n != "CMQ"}
    scipy.io.savemat(path, {"State": {n: getattr(state, n) for n in state._fieldnames}, "Coeffs": fields})
    with pytest.raises(DatcomFileError, match=r"no_cmq.mat: missing field Coeffs.CMQ"):
        load_datcom_mat(path)


def test_missing_state(tmp_path, lynx_mat):
    path = tmp_path / "no_state.mat"
    scipy.io.savemat(path, {"Coeffs": {"CA": lynx_mat["Coeffs"].CA}})
    with pytest.raises(DatcomFileError, match=r"no_state.mat: missing struct 'State'"):
        load_datcom_mat(path)
