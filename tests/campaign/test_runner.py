"""The runner: realization i is the same bits whatever the chunk size or device split."""

import tomllib
from pathlib import Path

import numpy as np
import pytest

from rocketmc.campaign import campaign_from_dict, read_campaign_tables, run_chunks, with_overrides

pytestmark = pytest.mark.slow  # campaigns or long flights: left out by make test-fast

CAMPAIGNS = Path(__file__).parents[2] / "campaigns"


def collect(campaign, chunk_size):
    chunks = list(run_chunks(campaign, chunk_size))[1:]  # the first item is the compile time
    outputs = {k: np.concatenate([c.outputs[k] for c in chunks]) for k in chunks[0].outputs}
    inputs = {k: np.concatenate([c.inputs[k] for c in chunks]) for k in chunks[0].inputs}
    return outputs, inputs


SERVO_DISPERSIONS = """[dispersions]
"gnc.servo.time_constant_s" = { dist = "uniform", low = 0.05, high = 0.1 }
"gnc.servo.offset_deg.0" = { dist = "normal", std = 0.5, low = -2.0, high = 2.0 }
"""


SENSORS = """[avionics]
part = "bmx160"

[avionics.barometer]
part = "ms5803_01ba"

[avionics.gnss]
part = "neo_m9n"

[avionics.canard_feedback]
part = "thesis"
noise_std = 0.1
bias_std = [0.2, 0.2, 0.2, 0.2]

"""


@pytest.mark.parametrize("name, sensors, other_chunk", [("lynx_nominal", False, 12), ("lynx_ballistic_ctrl_1s", True, 12),
                                                        ("lynx_ballistic_gnc_1s", False, 20)])  # fmt: skip
def test_same_bits_for_any_chunk_size(name, sensors, other_chunk):
    # Chunks of 5 (compiled batches of 16 flights, 8 per core, a padded last chunk) against chunks of 12 (the same
    # compiled batch, other chunk boundaries and padding) or of 20 (batches of 32: another program, once, on the full
    # GNC; a compilation costs ~25 s): the same realizations with turbulence, mass, thrust and wind draws, open loop,
    # and with the controller on and its servos dispersed, on raw sensors (datasheet
    # parts: their turn-on biases drawn per flight, their noise per block) and on the navigation filters (the
    # thesis's sensors, their walks and noise per block).
    path = CAMPAIGNS / f"{name}.toml"
    closed_loop = "ctrl" in name or "gnc" in name
    tables = read_campaign_tables(path)
    if closed_loop:
        tables["dispersions"].update(tomllib.loads(SERVO_DISPERSIONS)["dispersions"])
    if sensors:
        assert tables["gnc"]["navigation"] == "truth"
        tables["gnc"]["navigation"] = "sensors"
        tables.update(tomllib.loads(SENSORS))
    campaign = with_overrides(campaign_from_dict(tables, path.parent), n_realizations=24)
    a_out, a_in = collect(campaign, 5)
    b_out, b_in = collect(campaign, other_chunk)
    assert a_out.keys() == b_out.keys() and a_in.keys() == b_in.keys()
    for output in a_out:
        np.testing.assert_array_equal(a_out[output], b_out[output], err_msg=output)  # bit-identical (NaNs equal)
    for value in a_in:
        np.testing.assert_array_equal(a_in[value], b_in[value], err_msg=value)
    assert np.all(a_out["status"] == 0)
    assert len(np.unique(a_out["impact_north_m"])) == 24  # the realizations do differ
    if closed_loop:
        assert len(np.unique(a_in["gnc.servo.time_constant_s"])) == 24 and np.all(a_out["control_active_time_s"] > 8.9)
    if "gnc" in name:  # the filters' outputs, each flight its own
        assert len(np.unique(a_out["attitude_error_rms_window_rad"])) == 24
    if sensors:  # the drawn turn-on biases are inputs, one per axis
        assert len(np.unique(a_in["avionics.gyroscope.bias.2"])) == 24 and "avionics.canard_feedback.bias.3" in a_in
