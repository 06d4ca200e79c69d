"""tf helpers on nested lists agree with plain numpy matrix algebra."""

import math

import numpy as np
import pytest
from cc_sim import rot
from contact_control.frames import (
    IDENTITY,
    compose,
    inverse,
    quaternion_matrix,
    rotate_twist,
    rotation,
    times_transpose,
    transform,
    transpose_times,
)


def quaternion(axis, angle):
    a = np.asarray(axis, float) / np.linalg.norm(axis)
    return [*(a * math.sin(angle / 2)), math.cos(angle / 2)]


POSES = [
    ([0.0, 0.0, 0.0], [1, 0, 0], 0.0),
    ([0.4, 0.1, 0.5], [1, 0, 0], math.pi),
    ([-0.2, 0.3, 0.05], [0.3, -1.0, 0.2], 1.1),
]


@pytest.mark.parametrize(("xyz", "axis", "angle"), POSES)
def test_quaternion_and_transform_match_the_rotation(xyz, axis, angle):
    T = np.array(transform(xyz, quaternion(axis, angle)))
    assert T[:3, :3] == pytest.approx(rot(axis, angle))
    assert T[:3, 3] == pytest.approx(xyz)
    assert np.array(quaternion_matrix(0, 0, 0, 2.0)) == pytest.approx(np.eye(3))  # normalised


@pytest.mark.parametrize(("a", "b"), [(POSES[1], POSES[2]), (POSES[2], POSES[1])])
def test_compose_inverse_and_rotations(a, b):
    A = transform(a[0], quaternion(a[1], a[2]))
    B = transform(b[0], quaternion(b[1], b[2]))
    assert np.array(compose(A, B)) == pytest.approx(np.array(A) @ np.array(B))
    assert np.array(inverse(A)) == pytest.approx(np.linalg.inv(np.array(A)))
    assert np.array(compose(inverse(A), A)) == pytest.approx(np.array(IDENTITY))
    Ra, Rb = np.array(rotation(A)), np.array(rotation(B))
    assert np.array(transpose_times(rotation(A), rotation(B))) == pytest.approx(Ra.T @ Rb)
    assert np.array(times_transpose(A, B)) == pytest.approx(Ra @ Rb.T)  # 4x4 rows: their rotation blocks
    v = [0.1, -0.2, 0.3, 0.4, 0.5, -0.6]
    assert rotate_twist(rotation(A), v) == pytest.approx(np.concatenate([Ra @ v[:3], Ra @ v[3:]]))


def test_matrix_quaternion_inverts_quaternion_matrix_on_every_branch():
    """Shepperd's four branches (trace > 0, then the largest diagonal x, y, z) each round-trip."""
    import numpy as np
    from contact_control.frames import matrix_quaternion, quaternion_matrix

    rng = np.random.default_rng(3)
    cases = [rng.normal(size=4) for _ in range(200)]
    cases += [np.array(q, float) for q in ([1, 0, 0, 0.01], [0, 1, 0, 0.01], [0, 0, 1, 0.01], [0, 0, 0, 1])]
    for q in cases:
        q = q / np.linalg.norm(q) * (1 if q[3] >= 0 else -1)
        assert np.allclose(matrix_quaternion(quaternion_matrix(*q)), q, atol=1e-9), q
