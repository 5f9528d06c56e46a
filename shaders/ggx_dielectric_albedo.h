// The directional albedo of the white, single-scattering GGX dielectric with the Fresnel term of
// the microfacet (bsdf_ggx_dielectric.h, Closure::multiscatter, FresnelMode::Dielectric):
// E(mu, alpha, eta), the fraction of the light arriving from a direction of cosine mu that the
// lobe reflects or refracts, the rest being what microfacet masking and shadowing lose.
// Multiscatter GGX glass divides the lobe by it (Turquin et al. 2019), so that a non-absorbing
// rough dielectric conserves energy as Cycles' random walk does. Tabulated by quadrature of the
// lobe itself (no data files), in slices of eta each computed on first use, and interpolated
// linearly in mu, sqrt(alpha) and eta (or 1 / eta below 1).
#pragma once

namespace gdpt {

// mu in [0, 1], alpha in [0, 1], eta = n_t / n_i in [1/3, 3] (each clamped).
float ggx_dielectric_albedo(float mu, float alpha, float eta);

}  // namespace gdpt
