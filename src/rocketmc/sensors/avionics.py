"""The avionics: the rocket's sensors sampled at the GNC ticks, and the bus they write.

Each sensor turns the truth at the tick t_k into its measurement (``errors.sample``) and writes its
latest sample on the ``Bus``, the one thing navigation and control read. The accelerometer needs the
acceleration at t_k, a by-product of the period's first RK4 stage: it is sampled after the period's
integration (``sense_acceleration``) and so reaches the bus one tick after the others, as the input a
filter propagates with from t_k to t_{k+1}. Noise comes a block of ticks at a time from one stream per
sensor (``avionics_noise``), so that adding a sensor leaves every other draw unchanged.

Frames: NED from the pad, FRD body, each sensor's own axes (``rotation``: body → sensor, known to the
avionics). SI inside: m/s², rad/s, tesla, Pa, rad.
"""

from __future__ import annotations

import jax
import jax.numpy as jnp
import numpy as np
from jax import lax
from jax.extend.random import threefry2x32_p

from ..env.atmosphere import G0
from ..env.magnetic import first_order_field
from ..math import Quat, Vec3
from ..math.fusion import computed_once
from ..pytree import pytree_dataclass, static_field
from .errors import Channel, ChannelState, initial_channel, sample
from .parts import SENSORS


@pytree_dataclass
class Reading:
    """A sensor's latest delivered sample on the bus: value (n,) in its unit and frame; fresh: delivered at
    this tick; valid: some sample has been delivered."""

    value: jnp.ndarray
    fresh: jnp.ndarray
    valid: jnp.ndarray


@pytree_dataclass
class Bus:
    """Every sensor's latest sample. accelerometer: specific force [m/s²], sensor frame, sampled at the
    previous tick; gyroscope: body rates [rad/s], sensor frame; magnetometer: field [T], sensor frame;
    barometer: (1,) static pressure [Pa]; gnss: (6,) position [m] and velocity [m/s], NED from the pad;
    canard_feedback: (4,) servo positions δ1..δ4 [rad]."""

    accelerometer: Reading
    gyroscope: Reading
    magnetometer: Reading
    barometer: Reading
    gnss: Reading
    canard_feedback: Reading


@pytree_dataclass
class Mounted:
    """A 3-axis sensor on the airframe: its channel, rotation (3, 3) from body to sensor axes (the mounting,
    known to the avionics) and position_b (3,), where it sits in the body frame [m]."""

    channel: Channel
    rotation: jnp.ndarray
    position_b: jnp.ndarray


@pytree_dataclass
class Magnetometer:
    """A magnetometer (``Mounted``) in the flight's geomagnetic field, field_n (3,) [T, NED] at the pad and
    field_gradient (3, 3) its derivative along r_n [T/m] (None: the same everywhere), behind the airframe's soft
    iron (3, 3) and hard iron (3,) [T, sensor frame]."""

    sensor: Mounted
    field_n: jnp.ndarray
    field_gradient: jnp.ndarray | None
    soft_iron: jnp.ndarray
    hard_iron: jnp.ndarray


@pytree_dataclass
class Gnss:
    """A GNSS receiver: its channel (6 axes: position [m], velocity [m/s], NED), the sinusoidal position bias
    amplitude (3,) [m] · sin(2π·frequency [Hz]·t + phase (3,) [rad]), and the time of its first fix [s]."""

    channel: Channel
    amplitude: jnp.ndarray
    frequency: jnp.ndarray
    phase: jnp.ndarray
    first_fix_s: jnp.ndarray


@pytree_dataclass
class Avionics:
    """The sensors of one flight and the keys of their noise streams (by sensor name); canard_feedback is None
    on a rocket without canards."""

    accelerometer: Mounted
    gyroscope: Mounted
    magnetometer: Magnetometer
    barometer: Channel
    gnss: Gnss
    canard_feedback: Channel | None
    keys: dict


@pytree_dataclass
class AvionicsState:
    """The sensors' state as a few stacked arrays (each leaf of the flight loop's state costs kernels of its own
    every period): values (k,), each sensor's latest delivered sample in the bus's order (``sizes`` [i] values
    each, none for an absent sensor); fresh, valid (6,), its ``Reading`` flags; walks (w,), the random walks β
    of the channels that have one, in the bus's order; queues: each delayed channel's samples not yet
    delivered (``errors.ChannelState``'s queue and queued), by name; qbar: the dynamic pressure at the last
    accelerometer sample [Pa] (the vibration of the sensors sampled at the next tick). ``bus``: the ``Bus``."""

    values: jnp.ndarray
    fresh: jnp.ndarray
    valid: jnp.ndarray
    walks: jnp.ndarray
    queues: dict
    qbar: jnp.ndarray
    sizes: tuple = static_field()

    @property
    def bus(self) -> Bus:
        """Every sensor's ``Reading``: slices of the stacked arrays."""
        ends = np.cumsum(self.sizes)
        return Bus(*(Reading(self.values[end - n : end], self.fresh[i], self.valid[i])
                     for i, (n, end) in enumerate(zip(self.sizes, ends))))  # fmt: skip


def channels(av: Avionics) -> dict[str, Channel]:
    """Each sensor's ``Channel``, by name in the bus's order (none for an absent canard feedback)."""
    every = {"accelerometer": av.accelerometer.channel, "gyroscope": av.gyroscope.channel,
             "magnetometer": av.magnetometer.sensor.channel, "barometer": av.barometer, "gnss": av.gnss.channel,
             "canard_feedback": av.canard_feedback}  # fmt: skip
    return {name: c for name, c in every.items() if c is not None}


def initial_avionics(av: Avionics, like) -> AvionicsState:
    """Nothing sampled yet (an absent sensor's reading empty for good); ``like``: a scalar of the flight's dtype."""
    present = channels(av)
    dtype = jnp.result_type(like)
    sizes = tuple(present[name].n if name in present else 0 for name in SENSORS)
    no = jnp.zeros(len(SENSORS), bool)
    walks = sum(c.n for c in present.values() if c.walk_std is not None)
    queues = {name: initial_channel(c, like) for name, c in present.items() if c.delay}
    return AvionicsState(jnp.zeros(sum(sizes), dtype), no, no, jnp.zeros(walks, dtype),
                         {name: (q.queue, q.queued) for name, q in queues.items()}, jnp.zeros_like(like), sizes)  # fmt: skip


def _walk_slices(av: Avionics) -> dict[str, slice]:
    """Each walking channel's slice of ``AvionicsState.walks``, by name."""
    slices, start = {}, 0
    for name, c in channels(av).items():
        if c.walk_std is not None:
            slices[name], start = slice(start, start + c.n), start + c.n
    return slices


def noise_columns(av: Avionics) -> dict[str, slice]:
    """Each sensor's columns in ``avionics_noise``'s rows, by name, the sensors sampled at the same rate side by
    side (sensors that draw nothing left out)."""
    present = channels(av)
    columns, start = {}, 0
    for name in sorted(present, key=lambda name: present[name].every):  # stable: the bus's order within a rate
        if width := present[name].noise_per_tick:
            columns[name], start = slice(start, start + width), start + width
    return columns


def avionics_noise(av: Avionics, block, n_ticks: int):
    """The sensors' standard normals for block ``block`` of ``n_ticks`` ticks, (n_ticks, k), each sensor's
    columns (``noise_columns``) from its own stream (``normals``); None if no sensor draws any. A sensor sampled
    every m ticks draws for its samples only (each row repeated m times; blocks start at multiples of m: the
    campaign checks that m divides their length). One array, not one per sensor: the flight loop slices each of
    its inputs per tick (a kernel each), and six of them cost 8 % of a flight (measured)."""
    present, columns = channels(av), noise_columns(av)
    rates = {}
    for name in columns:
        rates.setdefault(present[name].every, []).append(name)
    drawn = []
    for every, names in rates.items():
        first = jnp.asarray(block).astype(jnp.uint32) * np.uint32(n_ticks // every)
        samples = first + jnp.arange(-(-n_ticks // every), dtype=jnp.uint32)
        draw = normals([av.keys[name] for name in names], [present[name].noise_per_tick for name in names], samples)
        drawn.append(jnp.repeat(draw, every, axis=0)[:n_ticks] if every > 1 else draw)
    return jnp.concatenate(drawn, axis=1) if len(drawn) > 1 else drawn[0] if drawn else None


def normals(keys, widths, samples):
    """Standard normals (len(samples), sum(widths)) in the flight's float dtype: stream i (key ``keys[i]``) fills
    ``widths[i]`` columns, each row a function of its sample index ``samples`` (uint32) alone.

    Counter-based: the stream's threefry-2x32 hash of the 64-bit counter sample·2^8 + j gives the two 32-bit
    words of pair j of its columns, each turned into a normal as ``jax.random.normal`` turns its 32-bit draws
    (23 bits to a uniform on (−1, 1), then √2·erf⁻¹, in float32 like the turbulence's). Half the hashes of
    ``jax.random.normal`` (whose partitionable threefry hashes once per 32-bit draw and XORs the two words), and
    every stream in one hash: the thesis's set 1.33x the closed loop's cost instead of 1.58x (one run). Both counter words
    come from the sample index: the threefry primitive's batching needs its operands batched alike."""
    pairs = [(i, j) for i, w in enumerate(widths) for j in range(-(-w // 2))]  # j < 2^8: a channel's ≤ 2n normals
    data = [jax.random.key_data(key) for key in keys]
    s = samples[:, None]
    shape = (s.shape[0], len(pairs))
    hi = jnp.broadcast_to(s >> np.uint32(24), shape)
    lo = (s << np.uint32(8)) | np.array([j for _, j in pairs], np.uint32)[None, :]
    # keys (1, pairs), not broadcast to the block: XLA's rolled threefry loop carries (and copies) its key schedule
    # at their shape (the draws 1.5x faster standalone, measured)
    k1, k2 = (jnp.stack([data[i][half] for i, _ in pairs])[None] for half in (0, 1))
    words = jnp.concatenate(threefry2x32_p.bind(k1, k2, hi, lo), axis=1)
    # stream i's w columns: the first words of its h = ⌈w/2⌉ pairs, then their second words (w odd: one unused);
    # as slices, not a gather of the columns: the draws 1.35x faster (measured)
    start, runs = 0, []
    for w in widths:
        h = -(-w // 2)
        runs += [words[:, start : start + h], words[:, len(pairs) + start : len(pairs) + start + w - h]]
        start += h
    words = jnp.concatenate(runs, axis=1)
    unit = lax.bitcast_convert_type((words >> np.uint32(9)) | np.uint32(0x3F800000), jnp.float32) - np.float32(1.0)
    low = np.nextafter(np.float32(-1.0), np.float32(1.0))  # jax.random.normal's open interval (−1, 1)
    uniform = jnp.maximum(low, unit * (np.float32(1.0) - low) + low)
    return (np.float32(np.sqrt(2.0)) * lax.erf_inv(uniform)).astype(jnp.result_type(float))


def _apply(matrix, v: Vec3):
    """``matrix`` (3, 3) times ``v``, as a (3,) array (written out: no small matrix product under vmap)."""
    return jnp.stack([matrix[i, 0] * v.x + matrix[i, 1] * v.y + matrix[i, 2] * v.z for i in range(3)])


def _read(av: Avionics, channel: Channel, state: AvionicsState, name: str, tick, truth, noise, enabled, qbar=0.0):
    """(delivered, fresh, new ``ChannelState``) of sensor ``name`` at ``tick`` (``errors.sample``); noise: the
    tick's row of ``avionics_noise``; qbar: the dynamic pressure [Pa] (vibration)."""
    columns, walks = noise_columns(av), _walk_slices(av)
    own = noise[columns[name]] if name in columns else None
    walk = state.walks[walks[name]] if name in walks else jnp.zeros(channel.n, state.walks.dtype)
    queue, queued = state.queues.get(name, (jnp.zeros((0, channel.n), walk.dtype), jnp.zeros(0, bool)))
    return sample(channel, ChannelState(walk, queue, queued), tick, truth, own, enabled, qbar)


def _written(av: Avionics, state: AvionicsState, read: dict, qbar) -> AvionicsState:
    """``state`` with the samples ``read`` ({name: ``_read``'s}) on the bus, each stacked array written at once."""
    ends = np.cumsum(state.sizes)
    values, fresh = [], []
    for i, (name, n, end) in enumerate(zip(SENSORS, state.sizes, ends)):
        old = state.values[end - n : end]
        values.append(jnp.where(read[name][1], read[name][0], old) if name in read else old)
        fresh.append(read[name][1] if name in read else state.fresh[i])
    fresh = jnp.stack(fresh)
    walks = [read[name][2].walk if name in read else state.walks[s] for name, s in _walk_slices(av).items()]
    queues = {name: (read[name][2].queue, read[name][2].queued) if name in read else q
              for name, q in state.queues.items()}  # fmt: skip
    return AvionicsState(jnp.concatenate(values), fresh, state.valid | fresh,
                         jnp.concatenate(walks) if walks else state.walks, queues, qbar, state.sizes)  # fmt: skip


def sense(av: Avionics, state: AvionicsState, tick, t, r_n: Vec3, v_n: Vec3, q_nb: Quat, omega_b: Vec3,
          deflections, environment, enabled, noise) -> AvionicsState:  # fmt: skip
    """Every sensor but the accelerometer at tick ``tick``, time t [s], from the truth: position r_n [m] and
    velocity v_n [m/s] of the CG (NED), attitude q_nb, body rates omega_b [rad/s], the servos' deflections
    (n_canards,) [rad]; environment: the flight's ``sim.params.Environment`` (the barometer reads its air's
    pressure); enabled: the sensors sample (False in the long descent periods); noise: this tick's row of
    ``avionics_noise``."""
    mag = av.magnetometer
    field_n = (Vec3(*(mag.field_n[i] for i in range(3))) if mag.field_gradient is None
               else first_order_field(mag.field_n, mag.field_gradient, r_n))  # fmt: skip
    field_s = _apply(mag.sensor.rotation, q_nb.rotate_inverse(field_n))
    gnss, fix = av.gnss, jnp.concatenate([r_n.to_array(), v_n.to_array()])
    if not gnss.channel.ideal:  # the slow sinusoidal position bias and its derivative, an error of the receiver
        omega = 2.0 * jnp.pi * gnss.frequency
        # sin and cos of ωt + φ by the angle sum: two transcendentals a tick instead of six (φ's are the flight's)
        sin_wt, cos_wt = computed_once(jnp.stack([jnp.sin(omega * t), jnp.cos(omega * t)]))
        sin_phase = sin_wt * jnp.cos(gnss.phase) + cos_wt * jnp.sin(gnss.phase)
        cos_phase = cos_wt * jnp.cos(gnss.phase) - sin_wt * jnp.sin(gnss.phase)
        fix = fix + jnp.concatenate([gnss.amplitude * sin_phase, gnss.amplitude * omega * cos_phase])
    truths = {
        "gyroscope": (av.gyroscope.channel, _apply(av.gyroscope.rotation, omega_b)),
        "magnetometer": (mag.sensor.channel, _apply(mag.soft_iron, Vec3(*field_s)) + mag.hard_iron),
        "barometer": (av.barometer, environment.air(environment.site_altitude_m - r_n.z).pressure[None]),
        "gnss": (gnss.channel, fix),
        "canard_feedback": (av.canard_feedback, deflections),
    }  # fmt: skip
    read = {}
    for name, (channel, truth) in truths.items():
        if channel is None:
            continue
        gate = enabled & (t >= gnss.first_fix_s) if name == "gnss" else enabled
        read[name] = _read(av, channel, state, name, tick, truth, noise, gate, state.qbar)
    return _written(av, state, read, state.qbar)


def specific_force_b(acceleration_n: Vec3, q_nb: Quat, omega_b: Vec3, omega_dot_b: Vec3, arm_b: Vec3,
                     gravity_mps2=G0) -> Vec3:  # fmt: skip
    """Specific force [m/s², body frame] at ``arm_b`` [m] from the CG: A(q)(a − g) + ω̇×r + ω×(ω×r), with the
    CG's acceleration a [m/s², NED] and g = (0, 0, gravity_mps2)."""
    at_cg = q_nb.rotate_inverse(acceleration_n - Vec3(0.0, 0.0, gravity_mps2))
    return at_cg + omega_dot_b.cross(arm_b) + omega_b.cross(omega_b.cross(arm_b))


def sense_acceleration(av: Avionics, state: AvionicsState, tick, specific_force: Vec3, qbar, enabled, noise) -> AvionicsState:
    """The accelerometer's sample of tick ``tick`` from the specific force at its position [m/s², body frame] and
    the dynamic pressure [Pa] then (the airframe's vibration)."""
    accel = av.accelerometer
    read = _read(av, accel.channel, state, "accelerometer", tick, _apply(accel.rotation, specific_force), noise,
                 enabled, qbar)  # fmt: skip
    return _written(av, state, {"accelerometer": read}, qbar)


def gyroscope_bias_b(av: Avionics, state: AvionicsState) -> Vec3:
    """The gyroscope's true bias now [rad/s, body frame]: its constant bias and its walk (the truth the navigation
    filters' estimate is scored against; scale-factor and cross-axis errors left out)."""
    gyro, walks = av.gyroscope, _walk_slices(av)
    walk = state.walks[walks["gyroscope"]] if "gyroscope" in walks else 0.0
    return to_body(gyro.rotation, gyro.channel.bias + walk)


def to_body(rotation, value) -> Vec3:
    """A sensor-frame (3,) value in the body frame: the mounting rotation (body → sensor) transposed."""
    return Vec3(*(sum(rotation[j, i] * value[j] for j in range(3)) for i in range(3)))
