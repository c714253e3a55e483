"""The built-in motor library: every file read, its numbers against the certified designation, finding a motor by
name, and the grain estimated from the casing against the one motor whose grain is known."""

import math
import re
import statistics
from pathlib import Path

import numpy as np
import pytest

from rocketmc.dynamics.motor_library import (
    MotorLibraryError,
    burn_time_s,
    casing_inertia_kgm2,
    estimated_grain,
    find_motor,
    impulse_class,
    matching_motors,
    motor_library,
    read_eng_entry,
)

LIBRARY = Path(__file__).parents[2] / "src" / "rocketmc" / "data" / "motors" / "library"


def certified(designation: str) -> tuple[str, int]:
    """The class letter and average thrust [N] a designation states (``4263-L1350-CS-P`` → ("L", 1350)), read
    from the name alone: the certification's numbers, independent of the curve."""
    letter, thrust = re.search(r"([A-O])(\d+)", designation).groups()
    return letter, int(thrust)


def test_every_file_of_the_library_is_read():
    """Each .eng file of the folder is one entry, its header's masses positive, the propellant under the total, its
    casing within the sizes of K to M motors (38 to 98 mm, under 1.2 m)."""
    files = sorted(p.name for p in LIBRARY.glob("*.eng"))
    library = motor_library()
    assert [e.path.name for e in library] == files and len(files) == 61
    for e in library:
        assert 0.0 < e.propellant_mass_kg < e.total_mass_kg, e.name
        assert 0.038 <= e.diameter_m <= 0.098 and 0.2 < e.length_m < 1.2, e.name
        assert 0.0 < e.burn_time_s and e.total_impulse_ns > 0.0, e.name


def test_total_impulse_is_the_designations_class():
    """The curve's total impulse lies in the class its designation certifies (K: 1280.01 to 2560 N·s), within 2 %
    of the class's ends: the certified class comes from the certifying firing, the file's curve is a digitised
    sample of it; the AeroTech M1939W's integrates to 10 367 N·s, 1.2 % over the M class's 10 240 N·s, the only
    one outside (its class from the curve is N). A class off by a letter is a factor 2 away."""
    outside = []
    for e in motor_library():
        letter, _ = certified(e.designation)
        top = 2.5 * 2.0 ** (ord(letter) - ord("A"))
        assert 0.5 * top / 1.02 < e.total_impulse_ns <= top * 1.02, (e.name, e.total_impulse_ns)
        if e.impulse_class != letter:
            outside.append(e.name)
    assert outside == ["AeroTech_M1939W"]


def test_impulse_class_letters():
    """The NAR's bands: A is (1.25, 2.5] N·s, each letter doubling; 1/2A below."""
    assert [impulse_class(x) for x in (2.5, 2.51, 1280.0, 1280.01, 2560.0, 5120.01, 1.0)] == [
        "A", "B", "J", "K", "K", "M", "1/2A"]  # fmt: skip


def test_average_thrust_is_the_designations_number():
    """Total impulse over the burn time (thrust ≥ 5 % of its maximum) against the designation's number (L1350:
    1350 N): within 20 % for every motor, and a median deviation under 3 %. The data: the median is 1.4 %, 51 of
    the 61 within 5 %, the largest K480W +16 % and M1939W −14 % (their files' curves are not the certifying
    firing's). The burn time matters: over the whole curve instead, the long tails of M750W and M1939W put them
    23 % under."""
    deviations = {e.name: e.average_thrust_n / certified(e.designation)[1] - 1.0 for e in motor_library()}
    assert max(abs(d) for d in deviations.values()) < 0.20, deviations
    assert statistics.median(abs(d) for d in deviations.values()) < 0.03
    assert deviations["Cesaroni_4263L1350-P"] == pytest.approx(0.0, abs=0.005)  # 1350 N within 0.5 %


def test_burn_time_at_five_percent_of_the_peak():
    """A trapezoid 0 → 1000 N in 1 s, flat to 3 s, 0 at 4 s: the thrust is at or above 50 N from 0.05 s to 3.95 s."""
    t, f = np.array([0.0, 1.0, 3.0, 4.0]), np.array([0.0, 1000.0, 1000.0, 0.0])
    assert burn_time_s(t, f) == pytest.approx(3.9, abs=1e-12)


@pytest.mark.parametrize("name", ["4263-L1350-CS-P", "cesaroni_4263l1350-p", "Cesaroni_4263L1350-P", "L1350",
                                  "l1350-p", "L1350-CS-P"])  # fmt: skip
def test_find_motor_by_designation_file_or_code(name):
    assert find_motor(name).name == "Cesaroni_4263L1350-P"


def test_find_motor_exact_name_before_code():
    """An exact file name wins even where the code alone would match another (K1000T's file name is its code)."""
    assert find_motor("AeroTech_K1000T").designation == "K1000T-P"
    assert find_motor("M1670").name == "Cesaroni_M1670"


def test_ambiguous_and_unknown_names():
    with pytest.raises(MotorLibraryError) as info:
        find_motor("K400")  # AeroTech's K400C and Cesaroni's 1597K400-14A
    assert str(info.value) == "'K400' is ambiguous: AeroTech_K400C, Cesaroni_1597K400-14A"
    with pytest.raises(MotorLibraryError) as info:
        find_motor("L13500")
    message = str(info.value)
    assert "\n" not in message and "not a motor of the library" in message and "Cesaroni_4263L1350-P" in message
    with pytest.raises(MotorLibraryError, match="rocketmc motors"):
        find_motor("hybrid")  # nothing close


def test_a_header_that_is_not_rasps_is_refused(tmp_path):
    path = tmp_path / "motor.eng"
    path.write_text("L1350 75 486 P 3.5 2.0 CTI\n0.1 1000\n3.0 1000\n3.2 0\n")  # propellant above the total
    with pytest.raises(MotorLibraryError, match="propellant less than the total"):
        read_eng_entry(path)
    path.write_text("0 0\n0.1 1000\n3.2 0\n")  # RocketPy's M1101 has no header: its first row is taken as one
    with pytest.raises(MotorLibraryError, match="not a RASP header"):
        read_eng_entry(path)


def test_search():
    assert [e.name for e in matching_motors("l1350")] == ["Cesaroni_4263L1350-P"]
    assert len(matching_motors("LOKI")) == 13 and len(matching_motors()) == 61
    assert matching_motors("zzz") == []


def test_grain_estimate_against_the_l1350s_known_grain():
    """The one motor whose grain is known (data/motors/SOURCE.md: the Lynx thesis models the L1350's as 75 mm outer,
    20 mm core, 532 mm long) against the estimate (66, 16.9, 349 mm). The thesis's grain is not the hardware's: it
    is as wide as the casing and longer than the whole 486 mm motor, at 927 kg/m³ for the header's mass, half
    any composite propellant's density. So the estimate is checked against what it must do, the header's mass at
    the assumed density inside the casing, and its distance from the thesis's is pinned: outer −12 %, core −15 %,
    length −34 %; the grain's transverse inertia about its centre (which is all the flight reads of it) is 2.3
    times smaller."""
    entry = find_motor("L1350")
    outer, core, length = estimated_grain(entry)
    assert (outer, length) == pytest.approx((0.066, 0.349), abs=1e-12)
    assert core == pytest.approx(0.01693, abs=1e-5)
    volume = math.pi / 4.0 * (outer**2 - core**2) * length
    assert entry.propellant_mass_kg / volume == pytest.approx(1815.0, rel=1e-12)
    assert outer < entry.diameter_m and length < entry.length_m
    thesis = (0.075, 0.020, 0.532)
    relative = [e / t - 1.0 for e, t in zip((outer, core, length), thesis)]
    assert relative == pytest.approx([-0.12, -0.153, -0.344], abs=0.002)

    def transverse(d_out, d_in, h):  # per kg, about the grain's centre
        return (3.0 * (d_out**2 + d_in**2) / 4.0 + h**2) / 12.0

    assert transverse(*thesis) / transverse(outer, core, length) == pytest.approx(2.3, abs=0.05)


def test_every_estimated_grain_fits_its_casing():
    """Outer diameter under the casing's, the length under the motor's, the core in [0, outer); the three motors
    whose header mass does not fit the estimated grain at the assumed density get a solid grain (core 0)."""
    solid = []
    for e in motor_library():
        outer, core, length = estimated_grain(e)
        assert 0.0 <= core < outer < e.diameter_m and 0.0 < length < e.length_m, e.name
        if core == 0.0:
            solid.append(e.name)
    assert solid == ["AeroTech_M1340W", "Cesaroni_1281K360-13A", "Cesaroni_3683L851-P"]


def test_casing_inertia_is_a_thin_tube():
    """m r² about the axis; m (r²/2 + L²/12) across: for the L1350's 1.5462 kg casing, 75 mm × 486 mm."""
    entry = find_motor("L1350")
    axial, transverse = casing_inertia_kgm2(entry, entry.casing_mass_kg)
    assert entry.casing_mass_kg == pytest.approx(3.5707 - 2.0245, rel=1e-12)
    assert axial == pytest.approx(1.5462 * 0.0375**2, rel=1e-12)
    assert transverse == pytest.approx(1.5462 * (0.0375**2 / 2 + 0.486**2 / 12), rel=1e-12)
