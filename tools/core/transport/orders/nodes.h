// The nodes of the multiple-scattering tables of `orders`: radius nodes dense near the ground and
// where the extinction is (one at the observer), view nodes per altitude split at that altitude's
// horizon (mu_h = -sqrt(1-(R/r)^2)) and dense next to it, sun nodes, azimuth nodes at cell centres
// on [0, pi]; the tables' cell layout and their interpolation.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "transport/orders/grid.h"
#include "transport/orders/settings.h"

namespace skybake::orders {

// The radius and view-node part of an interpolation: it depends on the point's radius and view
// cosine only, so the table rays compute it once, not once per order, sun node and azimuth.
struct RadialView {
  size_t ri = 0;             // lower radius node
  double wr[2] = {0, 0};     // weights of the radius nodes ri, ri + 1
  size_t k0[2] = {0, 0}, k1[2] = {0, 0};  // bracketing view nodes at each radius node
  double tk[2] = {0, 0};     // weight of k1
};
// The sun-angle and azimuth part of an interpolation (fixed for a table-ray step across all
// orders, so computed once).
struct SunAzimuth {
  uint16_t si = 0;  // lower sun node; kNoSun beyond the last node (no light)
  uint16_t q0 = 0;  // lower azimuth node
  float ts = 0.0f;  // weight of si + 1
  float tq = 0.0f;  // weight of q0 + 1
};
constexpr uint16_t kNoSun = 0xFFFF;

struct Nodes {
  double bottom_radius_m = 0.0;
  int nup = 0, ndn = 0, nphi = 0;
  double view_power = 2.0;
  size_t nw = 0;
  std::vector<double> radius;  // radius nodes (m); obs_index is the observer's
  size_t obs_index = 0;
  size_t ns = 0, nu = 0;       // sun nodes, view nodes per radius
  std::vector<double> sun_theta_rad;
  IntervalLocator sun_loc;  // over sun_theta_rad: SunAzimuthAt's lookup, once per table-ray step and cell

  double HorizonMu(double r) const;
  // View node k (0..nu-1, ascending mu) at radius r.
  double ViewMu(size_t k, double r) const;
  // The same placement at a fractional node index f within the set below (down) or above the horizon.
  double ViewMuAt(bool down, double f, double r) const;
  // Node k's solid-angle width in mu (trapezoid weight within its own set).
  double ViewWidth(size_t k, double r) const;
  // Fractional view index of mu at radius r (up and down parts are not interpolated across).
  void ViewIndex(double mu, double r, size_t* k0, size_t* k1, double* t) const;
  // Azimuth blend position of phi (0..pi, from the sun's plane): the lower node and the weight of
  // the next one (AzimuthBlend in nodes.cpp has the even blend).
  double AzimuthBlend(double phi, bool even, size_t* q0) const;
  size_t Cell(size_t ri, size_t si, size_t k, size_t q) const {
    return ((ri * ns + si) * nu + k) * static_cast<size_t>(nphi) + q;
  }
  // The view cosine of cell (ri, si, k, q) and its scattering cosine nu with the sun.
  void CellGeometry(size_t ri, size_t si, size_t k, size_t q, double* mu, double* nu_s) const;
  RadialView RadialViewAt(double r, double mu) const;
  SunAzimuth SunAzimuthAt(double theta_s, double cos_phi, bool even) const;
  // Interpolates table `tab` (cells x nw) at a point, accumulating weight * value into acc.
  void Interpolate(const Table& tab, const RadialView& rv, const SunAzimuth& sa, double weight, float* acc) const;
};

// The radius nodes' altitudes (m, ascending, 0 to H) for a column whose vertical optical depth from
// the ground to altitude h is tau_of(h): s.nr nodes uniform in s(h), each interval holding more
// than s.radius_dtau split into equal optical-depth pieces, at most s.radius_max nodes in all (the
// pieces are then the smallest that fit; nodes.cpp).
std::vector<double> RadiusNodeAltitudes(const OrdersSettings& s, const std::function<double(double)>& tau_of, double H);

// The nodes for settings s with a radius node at the observer's altitude.
Nodes BuildNodes(const AtmosphereModel& m, const OrdersSettings& s, double observer_altitude_m);

}  // namespace skybake::orders
