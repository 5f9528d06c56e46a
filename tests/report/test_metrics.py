"""Unit tests of the benchmark report's error measures (bench/report/metrics.py)."""
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "bench",
                                "report"))
import metrics as M  # noqa: E402


class Metrics(unittest.TestCase):
    def test_rel_mse_by_hand(self):
        ref = np.full((2, 2, 3), 0.5)
        x = ref.copy()
        x[0, 0, 0] = 0.6  # one value off by 0.1: 0.01 / (0.25 + 0.01) over 12 values
        self.assertAlmostEqual(M.rel_mse(x, ref), 0.01 / 0.26 / 12, places=12)
        self.assertEqual(M.rel_mse(ref, ref), 0.0)

    def test_denoised_rel_mse_removes_the_references_noise(self):
        # Truth t, an estimate with noise sigma, a reference of two halves with noise s each:
        # the denoised error estimates the estimate's error against t, not against the reference.
        rng = np.random.default_rng(3)
        t = np.full((400, 400, 3), 1.0)
        sigma, s = 0.05, 0.08
        x = t + rng.normal(0, sigma, t.shape)
        a, b = t + rng.normal(0, s, t.shape), t + rng.normal(0, s, t.shape)
        truth = M.rel_mse(x, t)
        self.assertAlmostEqual(truth, sigma ** 2 / 1.01, delta=0.02 * truth)
        self.assertGreater(M.rel_mse(x, 0.5 * (a + b)), 1.5 * truth)  # naive: off by s^2 / 2
        self.assertAlmostEqual(M.rel_mse_denoised(x, a, b), truth, delta=0.05 * truth)

    def test_half_noise_ratio(self):
        rng = np.random.default_rng(3)
        t = rng.uniform(0.2, 1.0, (256, 256, 3))
        ra, rb = (t + rng.normal(0, 0.02, t.shape) for _ in range(2))
        a, b = t + rng.normal(0, 0.1, t.shape), t + rng.normal(0, 0.1, t.shape)
        self.assertAlmostEqual(M.half_noise_ratio(a, b, 0.5 * (a + b), ra, rb), 1.0, delta=0.03)
        # Anti-correlated halves (a shared error e of opposite signs, sd 0.1) read the noise of
        # their mean high: Var (A - B) / 4 = (0.1^2 + 0.1^2 + 4 0.1^2) / 4 against
        # (0.1^2 + 0.1^2) / 4 for the mean, which e leaves out.
        e = rng.normal(0, 0.1, t.shape)
        a, b = a + e, b - e
        self.assertAlmostEqual(M.half_noise_ratio(a, b, 0.5 * (a + b), ra, rb), 3.0, delta=0.1)

    def test_rel_mse_between_sees_bias_not_noise(self):
        rng = np.random.default_rng(5)
        t = np.full((512, 512, 3), 0.8)

        def halves(mean, s):
            return mean + rng.normal(0, s, t.shape), mean + rng.normal(0, s, t.shape)

        same = M.rel_mse_between(halves(t, 0.1), halves(t, 0.15), block=4)
        self.assertLess(abs(same), 1.5e-4)  # naive: (0.1^2 + 0.15^2) / 32 / 0.65 = 1.6e-3
        biased = M.rel_mse_between(halves(t * 1.05, 0.1), halves(t, 0.15), block=4)
        # The noisy denominator leans the estimate up a little; the naive measure reads 4.1e-3.
        self.assertAlmostEqual(biased, 0.04 ** 2 / 0.65, delta=0.15 * 0.04 ** 2 / 0.65)

    def test_rel_mse_between_se_is_the_spread_over_draws(self):
        rng = np.random.default_rng(9)
        t = np.full((256, 256, 3), 0.8)

        def halves(s):
            return t + rng.normal(0, s, t.shape), t + rng.normal(0, s, t.shape)

        pairs = [(halves(0.1), halves(0.15)) for _ in range(12)]
        values = [M.rel_mse_between(a, b, block=4) for a, b in pairs]
        ses = [M.rel_mse_between_se(a, b, block=4) for a, b in pairs]
        # Without a bias the values scatter about 0 by the standard error the function states.
        self.assertAlmostEqual(np.std(values, ddof=1), np.mean(ses), delta=0.4 * np.mean(ses))
        self.assertLess(abs(np.mean(values)), 3 * np.mean(ses) / np.sqrt(len(values)))

    def test_ssim(self):
        rng = np.random.default_rng(1)
        img = rng.uniform(0.0, 1.0, (64, 64, 3))
        self.assertAlmostEqual(M.ssim(img, img), 1.0, places=9)
        noisy = img + rng.normal(0.0, 0.2, img.shape)
        worse = img + rng.normal(0.0, 0.4, img.shape)
        self.assertLess(M.ssim(worse, img), M.ssim(noisy, img))
        self.assertLess(M.ssim(noisy, img), 0.9)
        # A constant offset keeps the structure: the luminance term alone drops.
        self.assertGreater(M.ssim(np.clip(img * 0.9, 0, 1), img), M.ssim(noisy, img))

    def test_gradient_energy_ratio(self):
        # A linear ramp I(x) = x over w columns: sum I^2 against (w - 1) unit steps per row.
        w, h = 10, 4
        img = np.tile(np.arange(w, dtype=float)[None, :, None], (h, 1, 3))
        f = h * 3 * sum(x * x for x in range(w))
        g = h * 3 * (w - 1)
        self.assertAlmostEqual(M.gradient_energy_ratio(img), f / g)

    def test_block_mean_and_interpolation(self):
        img = np.arange(16, dtype=float).reshape(4, 4, 1)
        np.testing.assert_allclose(M.block_mean(img, 2)[..., 0], [[2.5, 4.5], [10.5, 12.5]])
        pts = [(1.0, 1e-2), (4.0, 1e-4)]  # slope -2 in log-log
        self.assertAlmostEqual(M.at_time(pts, 2.0), 1e-3, places=12)
        self.assertIsNone(M.at_time(pts, 8.0))


if __name__ == "__main__":
    unittest.main()
