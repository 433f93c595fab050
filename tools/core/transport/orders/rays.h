// The table rays of `orders`: for each (radius node, view node) a family of steps shared by every
// sun node and azimuth, placed uniformly in s = (tau_ref/tau_total + t/d)/2 so that they are dense
// where the medium is, with each step's exact transmittance weight and its sources' point.
#pragma once

#include <cstdint>
#include <vector>

#include "transport/orders/medium.h"
#include "transport/orders/nodes.h"

namespace skybake::orders {

struct Family {
  std::vector<double> t, r, mu;  // the step's representative point, its radius and view cosine
  // [step * nw + w]: the step's transmittance weight (StepWeight in rays.cpp).
  std::vector<float> wt;
  std::vector<float> ssc;      // [step * nw + w] scaled scattering coefficient sigma_s* at the step (m^-1)
  std::vector<RadialView> rv;  // the interpolation's radius/view part at each step
  // The same as table offsets: per step the 4 (radius, view) corners' cell offsets
  // Cell(ri, 0, k, 0) and weights (Cell() is a sum of a radius/view part and a sun/azimuth part).
  struct Corners {
    uint32_t off[4];
    float w[4];
  };
  std::vector<Corners> rc;
  std::vector<float> g;  // [step * nw + w] wt x ssc: the step's weight of J (m^-1 m)
  bool ground = false;
  double d = 0.0;
  std::vector<float> trans_end;  // at the ground
};

// fam[ri * nu + k] for every radius node ri and view node k.
std::vector<Family> BuildFamilies(const AtmosphereModel& m, const Medium& md, const Nodes& nodes, const OrdersSettings& s);

// The sun/azimuth interpolation position of step m of family f for the cell at radius r, sun
// zenith cosine cos_ts and scattering cosine nu (the sun's direction in the step's local frame).
SunAzimuth StepSunAzimuth(const Nodes& nodes, bool even, const Family& f, size_t m, double r, double cos_ts, double nu);

}  // namespace skybake::orders
