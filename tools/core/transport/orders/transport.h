// The transport step of `orders`: L_n = int T* sigma_s* J_n dt along every table ray (the step
// weights of rays.h) plus the ground's Lambertian reflection of the irradiance of L_{n-1}.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "transport/orders/rays.h"

namespace skybake::orders {

// Twilight: between two sun nodes the sources fall ~e-fold per degree, and a linear blend of the
// two nodes' J along a table ray overestimates the sky (clear, 1 deg nodes against 0.2 deg:
// +4-5 % RMS, up to 9 %, at sun 95-100 deg, at the nodes themselves). The exact log-linear blend
// would cost two transcendentals per wavelength in the innermost loop, so it is approximated by a
// factor on the linear blend, C = gbar_0^(1-t) gbar_1^t / ((1-t) gbar_0 + t gbar_1), gbar the mean
// J over the directions at the radius node and sun node (exact when the nodes' J have the same
// shape): tabulated per order at kLogBins + 1 values of t, per radius node, sun interval and
// wavelength, for the intervals from loglin_from_deg on.
constexpr size_t kLogBins = 16;

// A step's SunAzimuth as TransportContext stores it, in 32 bits: the sun node si (bits 0-5, 63 for
// kNoSun), the azimuth node q0 (bits 6-11) and the weights ts (bits 12-21) and tq (bits 22-31) in
// 10-bit fixed point, k / 1023 (within 4.9e-4 of the float weight; 0 and 1 exact). 4 bytes per
// (cell, step) instead of 12 (high's daylight tables: 4.6 MB per radius node), so that the
// default budget (288 MiB) holds the positions of all 65 of the thick skies' radius nodes. Every
// lookup reads the quantized weights, stored or computed (QuantizeSunAzimuth), so the two give
// the same bytes. The
// indices fit where a solve has at most 64 sun nodes and 64 azimuths (PositionsPackable); beyond
// (expert overrides only) every position is computed.
using PackedSunAzimuth = uint32_t;
constexpr uint32_t kWeightSteps = 1023;  // 10 bits
constexpr uint32_t kPackedNoSun = 63;    // 6 bits
inline uint32_t WeightCode(float t) { return static_cast<uint32_t>(std::lround(std::clamp(t, 0.0f, 1.0f) * static_cast<float>(kWeightSteps))); }
// k / 1023 for every code, as a table: the same floats as the division (correctly rounded either
// way), without the division's latency in every lookup.
inline constexpr std::array<float, kWeightSteps + 1> kWeightOfCode = [] {
  std::array<float, kWeightSteps + 1> w{};
  for (uint32_t k = 0; k <= kWeightSteps; ++k) w[k] = static_cast<float>(k) / static_cast<float>(kWeightSteps);
  return w;
}();
inline float WeightOfCode(uint32_t k) { return kWeightOfCode[k]; }
inline SunAzimuth QuantizeSunAzimuth(SunAzimuth p) {
  p.ts = WeightOfCode(WeightCode(p.ts));
  p.tq = WeightOfCode(WeightCode(p.tq));
  return p;
}
inline bool PositionsPackable(size_t ns, size_t nphi) { return ns <= 64 && nphi <= 64; }
inline PackedSunAzimuth PackSunAzimuth(const SunAzimuth& p) {
  const uint32_t si = p.si == kNoSun ? kPackedNoSun : p.si;
  return si | static_cast<uint32_t>(p.q0) << 6 | WeightCode(p.ts) << 12 | WeightCode(p.tq) << 22;
}
inline SunAzimuth UnpackSunAzimuth(PackedSunAzimuth v) {
  const uint32_t si = v & kPackedNoSun;  // the 6-bit fields' mask
  return {static_cast<uint16_t>(si == kPackedNoSun ? kNoSun : si), static_cast<uint16_t>(v >> 6 & kPackedNoSun),
          WeightOfCode(v >> 12 & kWeightSteps), WeightOfCode(v >> 22)};
}

struct TransportContext {
  const AtmosphereModel* m = nullptr;
  const Medium* md = nullptr;
  const Nodes* nodes = nullptr;
  const OrdersSettings* s = nullptr;
  const std::vector<Family>* fam = nullptr;
  // The sun/azimuth interpolation position of every (cell, step) of the first stored_radii radius
  // nodes, family by family and step by step ([PositionIndex]), shared by all orders (saves two
  // acos and a node search per lookup and order; order 1 fills it); the other radius nodes'
  // positions are computed per lookup. As many radius nodes as fit in
  // OrdersSettings::step_positions_mib (none where the indices do not fit the packed form:
  // PositionsPackable).
  std::vector<PackedSunAzimuth> sun_az;
  size_t stored_radii = 0;
  std::vector<double> cos_sun;  // cos of each sun node's zenith angle
  size_t loglin_first = 0;      // the first sun interval blended log-linearly (ns: none)
  size_t nd = 0;                // directions per (radius, sun)
  size_t nt = 0;                // steps per table ray
  size_t plane = 0;             // cells per family: ns x nphi

  bool Stored(size_t ri) const { return ri < stored_radii; }
  // Where cell (ri, si, k, q)'s position at step `step` is in sun_az: a family's cells at one step
  // are contiguous, in the order the transport visits them.
  size_t PositionIndex(size_t ri, size_t k, size_t step, size_t si, size_t q) const {
    return ((ri * nodes->nu + k) * nt + step) * plane + si * static_cast<size_t>(nodes->nphi) + q;
  }
  // Cell (ri, si, k, q)'s position at step `step` of family f; nu_s: the cell's scattering
  // cosine (Nodes::CellGeometry).
  SunAzimuth StepPosition(const Family& f, size_t step, size_t ri, size_t si, size_t k, size_t q, double nu_s) const {
    if (Stored(ri)) return UnpackSunAzimuth(sun_az[PositionIndex(ri, k, step, si, q)]);
    return ComputedStepPosition(f, step, ri, si, nu_s);
  }
  SunAzimuth ComputedStepPosition(const Family& f, size_t step, size_t ri, size_t si, double nu_s) const;
};

TransportContext MakeTransportContext(const AtmosphereModel& m, const Medium& md, const Nodes& nodes, const OrdersSettings& s,
                                      const std::vector<Family>& fam);

// E[si * nw + w]: the irradiance at the ground from a radiance table (upper view nodes at radius
// node 0), the sum over the up nodes and both azimuth halves of L mu dOmega.
void GroundIrradiance(const Nodes& nodes, int ndn, const Table& L, std::vector<float>* E);
// E interpolated to sun zenith theta_s (0 beyond the last sun node).
void InterpE(const Nodes& nodes, const std::vector<float>& E, double theta_s, float* out);

// acc[w] += the ground's Lambertian reflection, at the end of family f's ray (cell at radius r, sun
// zenith ts, scattering cosine nu), of the irradiance E; eg: scratch of nw floats.
void AddGroundReflection(const Nodes& nodes, const Medium& md, const Family& f, double r, double ts, double nu,
                         const std::vector<float>& E, float* eg, float* acc);

// The 4 sun/azimuth corners of position p: weights ws and table offsets sofs from so, the lower
// (sun, azimuth) corner, with sun_stride between sun nodes. A corner of weight 0 reads the first
// one (its own cell may lie past the table's end: the last azimuth or sun node with t = 0).
inline void SunAzimuthCorners(const SunAzimuth& p, size_t so, size_t sun_stride, float ws[4], size_t sofs[4]) {
  ws[0] = (1.0f - p.ts) * (1.0f - p.tq), ws[1] = (1.0f - p.ts) * p.tq, ws[2] = p.ts * (1.0f - p.tq), ws[3] = p.ts * p.tq;
  sofs[0] = so;
  sofs[1] = ws[1] != 0.0f ? so + 1 : so;
  sofs[2] = ws[2] != 0.0f ? so + sun_stride : so;
  sofs[3] = ws[3] != 0.0f ? so + sun_stride + 1 : so;
}

// Lout = the transport of the sources Jin, plus the ground's reflection of Lin's irradiance.
void Transport(const TransportContext& tc, const Table& Jin, const Table& Lin, Table* Lout);

// The two forms: cell by cell, 16 corners each (the plain one), and by families (the fast one).
void TransportCells(const TransportContext& tc, const Table& Jin, const Table& Lin, Table* Lout);
void TransportSplit(const TransportContext& tc, const Table& Jin, const Table& Lin, Table* Lout);

// The twilight factors C of Jin, [((ri * ns + si) * (kLogBins + 1) + b) * nw + w] for si >=
// loglin_first (empty if none), and their blend of a step's gathered J: jlo (the lower radius's
// corners) and jhi (the upper's) each times its factor at the step's sun interval, interpolated
// between the kLogBins + 1 tabulated t; the result in jlo.
std::vector<float> LogLinFactors(const TransportContext& tc, const Table& Jin);
// The factors at the tabulated bin b0 below position p's t, for the lower radius r0 (*c0) and
// the one above (*c1), each with bin b0 + 1's row nw floats after it, and t's place *tb between
// the two bins.
void LogLinBins(const TransportContext& tc, const std::vector<float>& cfac, const SunAzimuth& p, size_t r0, const float** c0,
                const float** c1, float* tb);
void LogBlend(const TransportContext& tc, const std::vector<float>& cfac, const SunAzimuth& p, size_t r0, float* jlo, const float* jhi);

}  // namespace skybake::orders
