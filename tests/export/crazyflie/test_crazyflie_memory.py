"""The Crazyflie's trajectory memory: cflib's own packing, and pptraj.c's float32 evaluation.

The packing is compared byte for byte with cflib 0.1.34's ``Poly4D.pack``; the
evaluation with a scalar transcription of crazyflie-firmware
``src/modules/src/pptraj.c`` (``piecewise_eval``, ``poly4d_eval``,
``polyval``, ``polyder``) written here one float32 operation at a time.
"""

from __future__ import annotations

import numpy as np
import pytest
from cflib.crazyflie.mem import Poly4D

from skyquill.errors import InputError
from skyquill.export.crazyflie.memory import (
    MEMORY_BYTES,
    PIECE_BYTES,
    FirmwareTrajectory,
    FlownUploads,
    end_states,
    flown_uploads,
    pack_pieces,
    unpack_pieces,
)
from skyquill.trajectory import Trajectory

f32 = np.float32


def random_table(pieces: int, seed: int = 0) -> np.ndarray:
    """Rows of a Crazyswarm CSV: durations 0.2-0.6 s, coefficients of all sizes."""
    rng = np.random.default_rng(seed)
    table = rng.normal(0.0, 1.0, (pieces, 33)) * 10.0 ** rng.integers(-3, 3, (pieces, 33))
    table[:, 0] = rng.uniform(0.2, 0.6, pieces)
    return table


def cflib_pack(table: np.ndarray) -> bytes:
    """cflib's own packing of the rows (Poly4D(duration, x, y, z, yaw).pack())."""
    data = bytearray()
    for row in table:
        axes = [Poly4D.Poly([float(v) for v in row[1 + 8 * a : 9 + 8 * a]]) for a in range(4)]
        data += Poly4D(float(row[0]), *axes).pack()
    return bytes(data)


def firmware_eval(data: bytes, t: float) -> tuple[list[list[float]], list[float]]:
    """pptraj.c piecewise_eval at ``t``, scalar float32: [pos, vel, acc, jerk] x (x, y, z)."""
    durations, coeffs = unpack_pieces(data)
    tt = f32(t)
    for k in range(durations.size):
        if tt <= durations[k]:
            p = [[f32(c) for c in axis] for axis in coeffs[k]]
            return _poly4d_eval(p, tt), [1.0] * 3
        tt = f32(tt - durations[k])
    p = [[f32(c) for c in axis] for axis in coeffs[-1]]
    pos = _poly4d_eval(p, durations[-1])[0]
    return [pos, [0.0] * 3, [0.0] * 3, [0.0] * 3], [0.0] * 3


def _poly4d_eval(p: list[list[np.float32]], t: np.float32) -> list[list[float]]:
    out = []
    for _ in range(4):
        out.append([float(_polyval(p[axis], t)) for axis in range(3)])
        for axis in range(4):  # polyder, in place
            for i in range(1, 8):
                p[axis][i - 1] = f32(f32(i) * p[axis][i])
            p[axis][7] = f32(0.0)
    return out


def _polyval(p: list[np.float32], t: np.float32) -> np.float32:
    x = f32(0.0)
    for i in range(7, -1, -1):
        x = f32(f32(x * t) + p[i])
    return x


@pytest.mark.parametrize("seed", range(3))
def test_packing_is_cflibs_byte_for_byte(seed: int) -> None:
    table = random_table(31, seed)
    data = pack_pieces(table)
    assert data == cflib_pack(table)
    assert len(data) == 31 * PIECE_BYTES == 4092 <= MEMORY_BYTES
    durations, coeffs = unpack_pieces(data)
    np.testing.assert_array_equal(durations, table[:, 0].astype(np.float32))
    np.testing.assert_array_equal(coeffs.reshape(31, 32), table[:, 1:].astype(np.float32))


def test_evaluation_is_the_firmwares_bit_for_bit() -> None:
    data = pack_pieces(random_table(7, seed=4))
    traj = FirmwareTrajectory.from_bytes(data)
    assert isinstance(traj, Trajectory) and traj.n_pieces == 7 and traj.dim == 3
    rng = np.random.default_rng(5)
    t = np.concatenate([rng.uniform(0.0, traj.duration, 300), traj.breakpoints])
    for order in range(4):
        got = traj.evaluate(t, order)
        for ti, row in zip(t, got, strict=True):
            want = firmware_eval(data, float(np.float32(ti)))[0][order]
            assert row.tolist() == want, (ti, order)


def test_past_the_end_holds_the_end_at_rest() -> None:
    table = random_table(2, seed=6)
    traj = FirmwareTrajectory.from_bytes(pack_pieces(table))
    end = traj.evaluate(np.array([traj.duration]))
    # The float32 durations may sum (float32) past the float64 total: then the firmware's hold.
    assert np.allclose(end, firmware_eval(pack_pieces(table), traj.duration)[0][0])
    start, last = end_states(traj)
    assert start.shape == last.shape == (3, 3)
    np.testing.assert_array_equal(start[0], traj.coeffs[0, :3, 0])


def test_uploads_on_one_clock_hold_between() -> None:
    a = FirmwareTrajectory.from_bytes(pack_pieces(random_table(3, seed=7)))
    b = FirmwareTrajectory.from_bytes(pack_pieces(random_table(2, seed=8)))
    flown = FlownUploads(np.array([0.5, a.duration + 1.5]), (a, b), a.duration + b.duration + 3.0)
    t = np.array([0.0, 0.25, 0.5 + a.duration + 0.5, flown.duration])
    pos, vel = flown.evaluate(t), flown.evaluate(t, 1)
    np.testing.assert_allclose(pos[0], a.evaluate(np.array([0.0]))[0])
    np.testing.assert_array_equal(vel[[0, 1, 2, 3]], 0.0)
    np.testing.assert_allclose(pos[2], a.evaluate(np.array([a.duration]))[0])
    np.testing.assert_allclose(pos[3], b.evaluate(np.array([b.duration]))[0])
    mid = np.array([flown.starts_s[1] + 0.1])
    np.testing.assert_allclose(
        flown.evaluate(mid, 2), b.evaluate(np.array([np.float32(0.1)]), 2), rtol=1e-6
    )
    assert flown.breakpoints[0] == 0.0 and flown.breakpoints[-1] == flown.duration
    two_d = flown_uploads([0.0], [pack_pieces(random_table(1))], 1.0, axes=2)
    assert two_d.evaluate(np.array([0.5])).shape == (1, 2)


def test_bad_memory_contents_are_refused() -> None:
    with pytest.raises(InputError, match="data: got 131 B, expected a positive multiple of 132"):
        unpack_pieces(bytes(131))
    with pytest.raises(InputError, match=r"data: got 4224 B \(32 pieces\), expected at most 4096"):
        unpack_pieces(pack_pieces(random_table(32)))
    table = random_table(1)
    table[0, 5] = 1e39
    with pytest.raises(InputError, match="table: got 1e\\+39 in row 0, expected a value float32"):
        pack_pieces(table)
    table = random_table(2)
    table[1, 0] = -0.5
    with pytest.raises(InputError, match=r"durations: got -0\.5 at piece 1, expected > 0 s"):
        FirmwareTrajectory.from_bytes(pack_pieces(table))
    nan = np.frombuffer(pack_pieces(random_table(1)), dtype="<f4").copy()
    nan[3] = np.nan
    with pytest.raises(InputError, match="coeffs: got a NaN or infinite coefficient"):
        FirmwareTrajectory.from_bytes(nan.tobytes())
    a = FirmwareTrajectory.from_bytes(pack_pieces(random_table(2)))
    with pytest.raises(InputError, match=r"starts_s: got .* expected each to start after"):
        FlownUploads(np.array([0.0, 0.1]), (a, a), 10.0)
    with pytest.raises(InputError, match="axes: got 4"):
        FlownUploads(np.array([0.0]), (a,), 10.0, axes=4)
