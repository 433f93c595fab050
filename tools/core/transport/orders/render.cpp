#include "transport/orders/render.h"

#include <cmath>
#include <limits>

#include "atmosphere/ray_sphere.h"
#include "io/fast_exp.h"

namespace skybake::orders {

namespace {

// Steps of a view ray uniform in the parameter s = (tau_ref/tau_tot + t/length)/2, computed on a
// fine uniform sub-grid at the middle wavelength (as the table rays). t(s) for increasing s walks
// on from the last interval (the same interval as a search, s_at being strictly increasing, and
// no locator built per ray).
class ViewStepper {
 public:
  ViewStepper(const Medium& md, int nf, double r, double mu, double length) : nf_(nf), length_(length), s_at_(static_cast<size_t>(nf) + 1) {
    const double R = md.m->bottom_radius_m;
    std::vector<double> cum(static_cast<size_t>(nf) + 1, 0.0);
    const size_t wref = md.wref;
    for (int p = 0; p < nf; ++p) {
      const double tm = (p + 0.5) * length / nf;
      const double rr = RadiusAt(r, mu, tm);
      cum[static_cast<size_t>(p) + 1] = cum[static_cast<size_t>(p)] + md.SigmaTAt(rr - R, false, wref) * length / nf;
    }
    const double tau_tot = std::max(cum.back(), 1e-12);
    for (int p = 0; p <= nf; ++p) s_at_[static_cast<size_t>(p)] = 0.5 * (cum[static_cast<size_t>(p)] / tau_tot + static_cast<double>(p) / nf);
  }
  double TOfS(double sv) {
    double u;
    if (sv <= s_at_.front()) {
      u = 0.0;
    } else if (sv >= s_at_.back()) {
      u = static_cast<double>(nf_);
    } else {
      while (s_i_ + 2 < s_at_.size() && s_at_[s_i_ + 1] <= sv) ++s_i_;
      u = static_cast<double>(s_i_) + (sv - s_at_[s_i_]) / (s_at_[s_i_ + 1] - s_at_[s_i_]);
    }
    return u * length_ / nf_;
  }

 private:
  int nf_;
  double length_;
  std::vector<double> s_at_;
  size_t s_i_ = 0;
};

// The view ray from radius r (the observer at observer_altitude_m) along mu: its points
// (Gauss-Legendre, 2 per step), their single-scattering weights, the segments' weights and the
// transmittance to the ground. What along a view ray does not depend on the sun or the azimuth is
// computed once per view zenith cosine and reused while the directions share it (a LUT row, an
// ambient ring: 32-128 directions per call).
void BuildViewRay(const RenderInputs& in, double observer_altitude_m, double r, double mu, const ViewSegment* segment, ViewRay* ray) {
  const Medium& md = *in.md;
  const AtmosphereModel& m = *in.m;
  const size_t nw = md.nw, nc = md.nc;
  const double R = m.bottom_radius_m, top = m.top_radius_m;
  const int nss = in.s->nss;
  ray->mu = mu;
  ray->pts.clear();
  ray->e.clear();
  ray->seg.clear();
  const size_t npts = 2 * static_cast<size_t>(nss);
  ray->pts.reserve(npts);
  ray->e.reserve(npts * nc * nw);
  if (segment != nullptr) ray->seg.reserve(npts * nw);
  const bool hits_ground = RayIntersectsGround(r, mu, R);
  // Segments never include the ground surface (transport/view_segment.h).
  ray->ground = segment == nullptr && hits_ground;
  if (segment != nullptr) {
    ray->length = SegmentEnd(m, observer_altitude_m, mu, *segment);
  } else {
    ray->length = DistanceToNearestBoundary(r, mu, R, top, hits_ground);
  }
  const double length = ray->length;
  std::vector<double> tau(nw, 0.0), tau_star(nw, 0.0);
  std::vector<float> st(nw), hwt(nw);
  ray->t_end.assign(nw, 1.0f);
  if (length <= 0.0) return;
  ViewStepper stepper(md, in.s->fine, r, mu, length);
  // Gauss-Legendre (2 points) on each step; optical depth accumulated with the same rule.
  static const double kG = 0.5773502691896257;
  double t_prev = 0.0;
  for (int step = 0; step < nss; ++step) {
    const double t0 = stepper.TOfS(static_cast<double>(step) / nss), t1 = stepper.TOfS(static_cast<double>(step + 1) / nss);
    const double h = t1 - t0;
    for (double g : {-kG, kG}) {
      const double t = 0.5 * (t0 + t1) + 0.5 * g * h;
      const double rr = RadiusAt(r, mu, t);
      // Optical depth from the observer to t: advance from t_prev with the midpoint value.
      const double tmid = 0.5 * (t_prev + t);
      const double rmid = RadiusAt(r, mu, tmid);
      const AtmosphereModel::Cell cmid = m.Locate(rmid - R), cell = m.Locate(rr - R);
      md.SigmaTView(cmid, st.data());
      for (size_t w = 0; w < nw; ++w) tau[w] += st[w] * (t - t_prev);
      if (segment != nullptr) {
        md.SigmaT(cmid, true, st.data());
        for (size_t w = 0; w < nw; ++w) tau_star[w] += st[w] * (t - t_prev);
      }
      t_prev = t;
      ray->pts.push_back({t, rr, ClampCosine(MuAt(r, mu, t, rr)), in.sun->Radius(rr, in.ss_scaled)});
      const float hw = static_cast<float>(segment == nullptr || segment->single_scattering ? 0.5 * h : 0.0);
      const size_t e0 = ray->e.size();
      ray->e.resize(e0 + nc * nw);
      // Single precision exp (the radiance is accumulated in float anyway), once per point for
      // all components.
      for (size_t w = 0; w < nw; ++w) hwt[w] = hw * ExpF(-static_cast<float>(tau[w]));
      for (size_t c = 0; c < nc; ++c) {
        md.SigmaS(c, cell, false, st.data());
        for (size_t w = 0; w < nw; ++w) ray->e[e0 + c * nw + w] = hwt[w] * st[w];
      }
      if (segment != nullptr) {
        const size_t s0 = ray->seg.size();
        ray->seg.resize(s0 + nw, 0.0f);
        for (size_t c = 0; c < nc; ++c) {
          md.SigmaS(c, cell, true, st.data());
          for (size_t w = 0; w < nw; ++w) ray->seg[s0 + w] += st[w];
        }
        for (size_t w = 0; w < nw; ++w) ray->seg[s0 + w] *= static_cast<float>(0.5 * h * std::exp(-tau_star[w]));
      }
    }
  }
  if (ray->ground) {
    // Finish the optical depth to the ground.
    const double tmid = 0.5 * (t_prev + length);
    const double rmid = RadiusAt(r, mu, tmid);
    md.SigmaTView(m.Locate(rmid - R), st.data());
    for (size_t w = 0; w < nw; ++w) ray->t_end[w] = static_cast<float>(std::exp(-(tau[w] + st[w] * (length - t_prev))));
  }
  if (segment == nullptr) {
    // Points behind an optical depth of ~88 at every wavelength (a grazing ray through a cloud
    // deck) have a weight of exactly 0 (ExpF underflows): their single scattering adds nothing,
    // so they are dropped (the same bytes, fewer sun lookups).
    const size_t per = nc * nw;
    size_t keep = ray->pts.size();
    while (keep > 0 && std::all_of(ray->e.begin() + static_cast<std::ptrdiff_t>((keep - 1) * per),
                                   ray->e.begin() + static_cast<std::ptrdiff_t>(keep * per), [](float v) { return v == 0.0f; })) {
      --keep;
    }
    ray->pts.resize(keep);
    ray->e.resize(keep * per);
  }
}

// a (b/a)^t, log-linear between a and b, where both are positive normal floats and their ratio
// is within 1e+-30 (else linear: a + (b - a) t), in float with ExpF/LogF (they agree with the
// double forms to ~3e-7 relative). Branch-free: with the transport module's -fno-trapping-math a
// loop of it vectorises, where powf is a library call per element.
inline float LogLinearBlend(float a, float b, float t) {
  const float ratio = b / a;
  const float geo = a * ExpF(t * LogF(ratio));
  const float lin = a + (b - a) * t;
  const int use_geo = static_cast<int>(a >= std::numeric_limits<float>::min()) & static_cast<int>(b >= std::numeric_limits<float>::min()) &
                      static_cast<int>(ratio > 1e-30f) & static_cast<int>(ratio < 1e30f);
  return use_geo ? geo : lin;
}

// Per-direction buffers.
struct DirectionScratch {
  std::vector<float> tsun, st, acc, ms0, ms1, pc, jv, jv1;
  std::vector<double> seg_ms, pv;
  DirectionScratch(size_t nw, size_t nc)
      : tsun(nw), st(nw), acc(nw), ms0(nw), ms1(nw), pc(nc * nw), jv(nw), jv1(nw), seg_ms(nw), pv(nw) {}
};

// The multiple-scattering source J_ms* at a segment's point pt, in its local frame (sun zenith
// cosine mus, scattering cosine nu), into x->jv: log-linear in the sun angle, as the sky's own
// multiple scattering (between twilight nodes 1 deg apart the sources fall ~e-fold, and a linear
// blend puts the fog between nodes ~10 % above the nodes'; docs/fog.md, "Limits").
void SegmentSource(const RenderInputs& in, const ViewPoint& pt, double mus, double nu, DirectionScratch* x) {
  const Nodes& nodes = *in.nodes;
  const size_t nw = in.md->nw;
  const double mus_c = std::clamp(mus, -1.0, 1.0);
  const double mu2 = pt.mu2;
  const double denom = std::sqrt(std::max(1e-12, (1.0 - mu2 * mu2) * (1.0 - mus_c * mus_c)));
  const double cphi2 = std::clamp((nu - mu2 * mus_c) / denom, -1.0, 1.0);
  const SunAzimuth sa = nodes.SunAzimuthAt(std::acos(mus_c), cphi2, in.s->azimuth_even);
  std::fill(x->jv.begin(), x->jv.end(), 0.0f);
  if (sa.si == kNoSun) return;
  const RadialView rv = nodes.RadialViewAt(pt.rr, mu2);
  std::fill(x->jv1.begin(), x->jv1.end(), 0.0f);
  nodes.Interpolate(in.res->jms, rv, SunAzimuth{sa.si, sa.q0, 0.0f, sa.tq}, 1.0, x->jv.data());
  if (sa.ts > 0.0f) {
    nodes.Interpolate(in.res->jms, rv, SunAzimuth{static_cast<uint16_t>(sa.si + 1), sa.q0, 0.0f, sa.tq}, 1.0, x->jv1.data());
    float* jv = x->jv.data();
    const float* jv1 = x->jv1.data();
    for (size_t w = 0; w < nw; ++w) jv[w] = LogLinearBlend(jv[w], jv1[w], sa.ts);
  }
}

// Along the view ray: single scattering into x->acc (unscaled medium on the view path unless
// ss_scaled_view, full phase), and for a segment its multiple scattering into x->seg_ms (the
// tabulated source attenuated by the scaled medium: the TMS split's L* part); then the ground's
// first reflection of the sun.
void MarchViewRay(const RenderInputs& in, const ViewRay& ray, double r, double ts, double nu, const ViewSegment* segment,
                  DirectionScratch* x) {
  const Medium& md = *in.md;
  const size_t nw = md.nw, nc = md.nc;
  for (size_t c = 0; c < nc; ++c) {
    // The phase times the sun's irradiance (per direction, not per point).
    md.phase[c]->EvalAll(nu, nw, x->pv.data());
    for (size_t w = 0; w < nw; ++w) x->pc[c * nw + w] = static_cast<float>(x->pv[w] * md.sun_e[w]);
  }
  std::fill(x->acc.begin(), x->acc.end(), 0.0f);
  std::fill(x->seg_ms.begin(), x->seg_ms.end(), 0.0);
  for (size_t p = 0; p < ray.pts.size(); ++p) {
    const ViewPoint& pt = ray.pts[p];
    const double mus = SunMuAt(r, std::cos(ts), nu, pt.t, pt.rr);
    if (segment == nullptr || segment->single_scattering) {
      in.sun->TransmittanceAt(pt.sun_r, mus, in.ss_scaled, x->tsun.data());
      const float* e = &ray.e[p * nc * nw];
      std::fill(x->st.begin(), x->st.end(), 0.0f);
      for (size_t c = 0; c < nc; ++c) {
        for (size_t w = 0; w < nw; ++w) x->st[w] += e[c * nw + w] * x->pc[c * nw + w];
      }
      for (size_t w = 0; w < nw; ++w) x->acc[w] += x->st[w] * x->tsun[w];
    }
    if (segment != nullptr) {
      SegmentSource(in, pt, mus, nu, x);
      const float* sg = &ray.seg[p * nw];
      for (size_t w = 0; w < nw; ++w) x->seg_ms[w] += sg[w] * x->jv[w];
    }
  }
  if (ray.ground) {
    const double R = in.m->bottom_radius_m;
    const double mus_g = SunMuAt(r, std::cos(ts), nu, std::max(0.0, ray.length), R);
    if (mus_g > -0.5) {
      in.sun->Transmittance(R, mus_g, in.ss_scaled, x->tsun.data());
      for (size_t w = 0; w < nw; ++w) {
        x->acc[w] += static_cast<float>(ray.t_end[w] * md.albedo[w] / kPi * md.sun_e[w] * std::max(0.0, mus_g)) * x->tsun[w];
      }
    }
  }
}

// L_ms from the table at the observer radius for view cosine mu, azimuth cosine cphi, into
// out[w] added to x->acc: linear in the view and azimuth nodes, log-linear between the two sun
// nodes ls, a (b/a)^t, where both are positive normal floats and their ratio is within 1e+-30
// (else linear): LogLinearBlend.
void ObserverMultipleScattering(const RenderInputs& in, double r, double ts, double mu, double cphi, const Lerp& ls,
                                DirectionScratch* x, double* out) {
  const Nodes& nodes = *in.nodes;
  const std::vector<float>& ms = in.res->ms;
  const size_t nw = in.md->nw, nphi = static_cast<size_t>(in.s->nphi), nd = nodes.nu * nphi;
  std::fill(x->ms0.begin(), x->ms0.end(), 0.0f);
  std::fill(x->ms1.begin(), x->ms1.end(), 0.0f);
  if (ts <= nodes.sun_theta_rad.back()) {
    size_t k0, k1;
    double tk;
    nodes.ViewIndex(mu, r, &k0, &k1, &tk);
    size_t q0;
    const double tq = nodes.AzimuthBlend(std::acos(std::clamp(cphi, -1.0, 1.0)), in.s->azimuth_even, &q0);
    for (int ds = 0; ds < 2; ++ds) {
      float* dst = ds ? x->ms1.data() : x->ms0.data();
      const size_t si = ls.i + static_cast<size_t>(ds);
      for (int dk = 0; dk < 2; ++dk) {
        for (int dq = 0; dq < 2; ++dq) {
          const float wgt = static_cast<float>((dk ? tk : 1.0 - tk) * (dq ? tq : 1.0 - tq));
          const float* v = &ms[((si * nd) + (dk ? k1 : k0) * nphi + q0 + static_cast<size_t>(dq)) * nw];
          for (size_t w = 0; w < nw; ++w) dst[w] += wgt * v[w];
        }
      }
    }
  }
  const float tf = static_cast<float>(ls.t);
  for (size_t w = 0; w < nw; ++w) {
    out[w] = static_cast<double>(x->acc[w]) + static_cast<double>(std::max(0.0f, LogLinearBlend(x->ms0[w], x->ms1[w], tf)));
  }
}

}  // namespace

void Render(const RenderInputs& in, double observer_altitude_m, double sun_zenith_rad, const std::vector<std::array<double, 3>>& dirs,
            const ViewSegment* segment, std::vector<double>* out, std::vector<double>* single) {
  const size_t nw = in.md->nw;
  const double r = in.m->bottom_radius_m + observer_altitude_m;
  const double ts = sun_zenith_rad;
  out->assign(dirs.size() * nw, 0.0);
  if (single != nullptr) single->assign(dirs.size() * nw, 0.0);
  const Lerp ls = Locate(in.nodes->sun_loc, ts);
  DirectionScratch x(nw, in.md->nc);
  // Whole view rays are kept across calls (ViewRayCache); a segment's is built per view cosine.
  ViewRay local;
  std::shared_ptr<const ViewRay> cached;
  const ViewRay* cur = nullptr;
  for (size_t d = 0; d < dirs.size(); ++d) {
    const double mu = std::clamp(dirs[d][2], -1.0, 1.0);
    const double sn = std::sqrt(std::max(0.0, 1.0 - mu * mu));
    const double cphi = sn > 1e-12 ? dirs[d][0] / sn : 1.0;
    const double nu = dirs[d][0] * std::sin(ts) + mu * std::cos(ts);  // the sun is (sin ts, 0, cos ts)
    if (cur == nullptr || mu != cur->mu) {
      if (segment == nullptr) {
        cached = in.cache->Get(observer_altitude_m, mu, [&](ViewRay* ray) { BuildViewRay(in, observer_altitude_m, r, mu, nullptr, ray); });
        cur = cached.get();
      } else {
        BuildViewRay(in, observer_altitude_m, r, mu, segment, &local);
        cur = &local;
      }
    }
    MarchViewRay(in, *cur, r, ts, nu, segment, &x);
    if (segment != nullptr) {
      for (size_t w = 0; w < nw; ++w) (*out)[d * nw + w] = x.acc[w] + std::max(0.0, x.seg_ms[w]);
      continue;
    }
    if (single != nullptr) {
      for (size_t w = 0; w < nw; ++w) (*single)[d * nw + w] = static_cast<double>(x.acc[w]);
    }
    ObserverMultipleScattering(in, r, ts, mu, cphi, ls, &x, &(*out)[d * nw]);
  }
}

}  // namespace skybake::orders
