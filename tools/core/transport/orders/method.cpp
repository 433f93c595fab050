// The `orders` sky method (transport/method_orders.h has the method's outline): the phases run in
// the constructor - the medium, the sun tables, the table nodes, the multiple-scattering solve -
// and the render answers each request from their results.
#include <fmt/format.h>

#include "transport/method_orders.h"
#include "transport/orders/render.h"

namespace skybake {

namespace {

class OrdersMethod : public SkyMethod {
 public:
  OrdersMethod(const AtmosphereModel& model, const SkyMethodOptions& options, const ProgressFn& progress)
      : m_(model), s_(orders::SettingsFor(options)) {
    ss_scaled_ = s_.ss_scaled && s_.max_orders >= 2;
    md_ = orders::PrepareMedium(m_, s_, ss_scaled_ && s_.ss_scaled_view > 0);
    sun_ = orders::BuildSunTables(m_, md_, s_);
    nodes_ = orders::BuildNodes(m_, s_, options.observer_altitude_m);
    res_ = orders::SolveMultipleScattering(m_, md_, sun_, nodes_, s_, progress);
  }

  std::string Name() const override { return "orders"; }

  std::string Describe() const override {
    return fmt::format(
        "method: orders\nradius_nodes: {}\nview_nodes: {} up + {} down per altitude\nazimuth_nodes: {}\n"
        "sun_nodes: {}\nray_steps: {}\nview_steps: {}\ntruncation_deg: {}\nkernel: {}\norders_computed: {}\n"
        "tail_extrapolated: {}\nlast_order_fraction: {:.3g}\ntolerance: {}\nsingle_scattering_attenuation: {}\n",
        nodes_.radius.size(), s_.nup, s_.ndn, s_.nphi, s_.sun_deg.size(), s_.nt, s_.nss, md_.ConesText(),
        s_.kernel_sub > 0 ? fmt::format("basis-integrated, {} sub-intervals", s_.kernel_sub) : std::string("phase at the nodes"),
        res_.orders_done, res_.tail ? "true" : "false", res_.last_fraction, s_.tolerance, ss_scaled_ ? "delta-scaled" : "unscaled");
  }

  void Radiance(double observer_altitude_m, double sun_zenith_rad, const std::vector<std::array<double, 3>>& dirs,
                std::vector<double>* out) const override {
    orders::Render(Inputs(), observer_altitude_m, sun_zenith_rad, dirs, nullptr, out, nullptr);
  }
  // L_1 of the split L = L_1 + L_ms (the exact march of the output ray), computed beside L.
  bool SingleScatteringRadiance(double observer_altitude_m, double sun_zenith_rad, const std::vector<std::array<double, 3>>& dirs,
                                std::vector<double>* out) const override {
    std::vector<double> total;
    orders::Render(Inputs(), observer_altitude_m, sun_zenith_rad, dirs, nullptr, &total, out);
    return true;
  }
  bool SupportsSegments() const override { return true; }
  void SegmentRadiance(double observer_altitude_m, double sun_zenith_rad, const std::vector<std::array<double, 3>>& dirs,
                       const ViewSegment& segment, std::vector<double>* out) const override {
    orders::Render(Inputs(), observer_altitude_m, sun_zenith_rad, dirs, &segment, out, nullptr);
  }

 private:
  orders::RenderInputs Inputs() const { return orders::RenderInputs{&m_, &md_, &sun_, &nodes_, &s_, &res_, ss_scaled_, &cache_}; }

  const AtmosphereModel& m_;
  orders::OrdersSettings s_;
  bool ss_scaled_ = false;  // s_.ss_scaled with multiple-scattering orders (max_orders >= 2)
  orders::Medium md_;
  orders::SunTables sun_;
  orders::Nodes nodes_;
  orders::SolveResult res_;
  mutable orders::ViewRayCache cache_;
};

}  // namespace

std::unique_ptr<SkyMethod> MakeOrdersMethod(const AtmosphereModel& model, const SkyMethodOptions& options,
                                            const ProgressFn& progress) {
  return std::make_unique<OrdersMethod>(model, options, progress);
}

}  // namespace skybake
