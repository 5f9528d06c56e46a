// GGX's directional albedo E(mu, alpha): the fraction of light a white, Fresnel-free GGX
// reflection lobe (bsdf_ggx_reflection.h) reflects from a direction of cosine mu, and its cosine
// average E_avg(alpha) = 2 int_0^1 E(mu) mu dmu. Tabulated once, on first use, by quadrature of
// the lobe itself (no data files), and interpolated bilinearly in (mu, sqrt(alpha)); E_avg is the
// exact average of the interpolated E, so the multiple-scattering lobe built on them
// (bsdf_ggx_multiscatter.h) conserves energy to the table's accuracy.
#pragma once

namespace gdpt {

// mu in [0, 1] (clamped), alpha clamped to [0, 1].
float ggx_albedo(float mu, float alpha);
float ggx_average_albedo(float alpha);

}  // namespace gdpt
