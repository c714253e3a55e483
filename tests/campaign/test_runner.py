"""The runner: realization i is the same bits whatever the chunk size or device split."""

from pathlib import Path

import numpy as np
import pytest

from rocketmc.campaign import parse_campaign, run_chunks

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


@pytest.mark.parametrize("name", ["lynx_nominal", "lynx_ballistic_ctrl_1s"])
def test_same_bits_for_any_chunk_size(name):
    # Chunks of 5 (compiled batches of 16 flights, 8 per core, a padded last chunk) against chunks of
    # 20 (batches of 32): the same realizations with turbulence, mass, thrust and wind draws, open loop,
    # and with the controller on (perfect navigation) and its servos dispersed.
    path = CAMPAIGNS / f"{name}.toml"
    campaign = parse_campaign(path.read_text().replace("[dispersions]\n", SERVO_DISPERSIONS if "ctrl" in name else "[dispersions]\n"),
                              path.parent).with_overrides(n_realizations=24)  # fmt: skip
    a_out, a_in = collect(campaign, 5)
    b_out, b_in = collect(campaign, 20)
    assert a_out.keys() == b_out.keys() and a_in.keys() == b_in.keys()
    for name in a_out:
        np.testing.assert_array_equal(a_out[name], b_out[name], err_msg=name)  # bit-identical (NaNs equal)
    for name in a_in:
        np.testing.assert_array_equal(a_in[name], b_in[name], err_msg=name)
    assert np.all(a_out["status"] == 0)
    assert len(np.unique(a_out["impact_north_m"])) == 24  # the realizations do differ
    if "ctrl" in name:
        assert len(np.unique(a_in["gnc.servo.time_constant_s"])) == 24 and np.all(a_out["control_active_time_s"] > 8.9)
