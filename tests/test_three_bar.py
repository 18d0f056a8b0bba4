import numpy as np

from plantmech.mechanisms.three_bar import tip_position, tip_rate


def test_tip_and_rate_against_finite_differences():
    psi = np.linspace(0, 2 * np.pi, 2001)
    carrier = 0.4 - psi
    rel = psi + 0.3 * np.sin(psi)
    arm = carrier + rel
    ratio = 1 + 0.3 * np.cos(psi)
    tip = tip_position(120.0, 300.0, carrier, arm)
    assert np.allclose(tip[0], [120 * np.cos(0.4) + 300 * np.cos(0.4),
                                120 * np.sin(0.4) + 300 * np.sin(0.4)])
    fd = np.gradient(tip, psi, axis=0)
    rate = tip_rate(120.0, 300.0, carrier, arm, ratio)
    assert np.abs(fd[1:-1] - rate[1:-1]).max() < 1e-3


def test_broadcasts_over_a_population():
    carrier = np.zeros((3, 5))
    arm = np.full((3, 5), np.pi / 2)
    L1 = np.array([[1.0], [2.0], [3.0]])
    tip = tip_position(L1, 10.0, carrier, arm)
    assert tip.shape == (3, 5, 2)
    assert np.allclose(tip[:, 0, 0], [1, 2, 3]) and np.allclose(tip[..., 1], 10)
