"""Image error measures of the benchmark report (numpy only).

Images are float arrays (height, width, 3) in scene-linear RGB.
- rel_mse: mean over pixels and channels of (x - r)^2 / (r^2 + eps), eps = 0.01 as in the
  gradient-domain literature, so dark pixels do not dominate.
- rel_mse_denoised: the error against the truth estimated from a noisy reference r = (r1 + r2) / 2
  made of two independent halves: E|x - r|^2 = E|x - t|^2 + E|r - t|^2 and
  E|r1 - r2|^2 = 4 E|r - t|^2, so the reference's own noise is subtracted.
- rel_mse_between: the same correction for two noisy images (each from two halves), on block
  means: how far apart two engines' converged images are; rel_mse_between_se its standard error.
- half_noise_ratio: what two halves of a render say its noise is, (A - B)^2 / 4 relative, over
  the render's true relMSE (rel_mse_denoised): 1 for independent halves of an unbiased render,
  above 1 when the halves are anti-correlated (the Feature reconstruction's error estimate reads
  its noise terms that much too high).
- ssim: structural similarity (Wang et al. 2004; 11-tap Gaussian window, sigma 1.5) of the
  luminance after a display transform (clip to [0, 1], gamma 1/2.2).
- gradient_energy_ratio: the survey's predicted improvement of gradient sampling,
  ||F||^2 / ||G||^2, F the image and G its finite differences (Hua et al. 2019, eq. 20).
"""
import numpy as np

EPS = 1e-2


def rel_mse(x, ref, eps=EPS):
    return float(np.mean((x - ref) ** 2 / (ref ** 2 + eps)))


def rel_mse_denoised(x, ref_a, ref_b, eps=EPS):
    ref = 0.5 * (ref_a + ref_b)
    noise = 0.25 * np.mean((ref_a - ref_b) ** 2 / (ref ** 2 + eps))
    return float(np.mean((x - ref) ** 2 / (ref ** 2 + eps)) - noise)


def half_noise_ratio(a, b, x, ref_a, ref_b, eps=EPS):
    """The halves' estimate of x's noise, mean (a - b)^2 / 4 / (r^2 + eps), over x's relMSE
    against the noisy reference (its noise subtracted); x = (a + b) / 2 up to the halves' counts."""
    ref = 0.5 * (ref_a + ref_b)
    estimate = 0.25 * np.mean((a - b) ** 2 / (ref ** 2 + eps))
    return float(estimate / rel_mse_denoised(x, ref_a, ref_b, eps))


def _between_terms(a, b, block, eps):
    """rel_mse_between's term per block and channel."""
    a1, a2, b1, b2 = (block_mean(i, block) for i in (*a, *b))
    ma, mb = 0.5 * (a1 + a2), 0.5 * (b1 + b2)
    d = (ma - mb) ** 2 - 0.25 * (a1 - a2) ** 2 - 0.25 * (b1 - b2) ** 2
    return d / (mb ** 2 + eps)


def rel_mse_between(a, b, block=1, eps=EPS):
    """relMSE between two noisy images, each given as two independent halves, on block x block
    means, with both images' noise subtracted: the squared bias between what they converge to."""
    return float(np.mean(_between_terms(a, b, block, eps)))


def rel_mse_between_se(a, b, block=1, eps=EPS):
    """The standard error of rel_mse_between from the spread of its per-block terms: a value
    within a few of these of 0 is the references' noise, not a difference."""
    t = _between_terms(a, b, block, eps).mean(axis=-1)  # a block's channels share their noise
    return float(np.std(t) / np.sqrt(t.size))


def block_mean(img, block):
    """Means over block x block tiles (the image cropped to whole tiles)."""
    h, w = (img.shape[0] // block) * block, (img.shape[1] // block) * block
    t = img[:h, :w].reshape(h // block, block, w // block, block, -1)
    return t.mean(axis=(1, 3))


def luminance(img):
    return img[..., 0] * 0.2126 + img[..., 1] * 0.7152 + img[..., 2] * 0.0722


def display(img):
    """Scene-linear RGB to display values in [0, 1] (clip, gamma 1/2.2)."""
    return np.clip(img, 0.0, 1.0) ** (1.0 / 2.2)


def _gaussian_blur(img, sigma=1.5, radius=5):
    k = np.exp(-0.5 * (np.arange(-radius, radius + 1) / sigma) ** 2)
    k /= k.sum()
    pad = np.pad(img, radius, mode="reflect")
    rows = sum(k[i] * pad[:, i:i + img.shape[1]] for i in range(2 * radius + 1))
    return sum(k[i] * rows[i:i + img.shape[0], :] for i in range(2 * radius + 1))


def ssim(x, ref):
    a, b = luminance(display(x)), luminance(display(ref))
    c1, c2 = 0.01 ** 2, 0.03 ** 2
    mu_a, mu_b = _gaussian_blur(a), _gaussian_blur(b)
    var_a = _gaussian_blur(a * a) - mu_a ** 2
    var_b = _gaussian_blur(b * b) - mu_b ** 2
    cov = _gaussian_blur(a * b) - mu_a * mu_b
    s = ((2 * mu_a * mu_b + c1) * (2 * cov + c2)) / ((mu_a ** 2 + mu_b ** 2 + c1) *
                                                     (var_a + var_b + c2))
    return float(np.mean(s))


def gradient_energy_ratio(img):
    dx = img[:, 1:] - img[:, :-1]
    dy = img[1:, :] - img[:-1, :]
    f = float(np.sum(img ** 2))
    g = float(np.sum(dx ** 2) + np.sum(dy ** 2))
    return f / g if g > 0 else float("inf")


def at_time(points, t):
    """relMSE at time t interpolated in log-log between measured (seconds, relMSE) points;
    None outside the measured range or where an error is not positive."""
    pts = sorted((s, e) for s, e in points if s > 0 and e > 0)
    for (s0, e0), (s1, e1) in zip(pts, pts[1:]):
        if s0 <= t <= s1:
            w = (np.log(t) - np.log(s0)) / (np.log(s1) - np.log(s0)) if s1 > s0 else 0.0
            return float(np.exp((1 - w) * np.log(e0) + w * np.log(e1)))
    return None
