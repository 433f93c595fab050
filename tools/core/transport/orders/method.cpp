// The `orders` sky method (transport/method_orders.h has the method's outline): the phases run in
// the constructor - the medium, the sun tables, the table nodes, the multiple-scattering solve -
// and the render answers each request from their results. With the twilight split (split.h) it
// holds two such solves, the daylight and the twilight one, and blends their answers.
#include <fmt/format.h>

#include <optional>
#include <stdexcept>

#include "transport/method_orders.h"
#include "transport/orders/render.h"
#include "transport/orders/split.h"

namespace skybake {

namespace {

// One solve: the medium, the sun tables, the nodes and the orders for settings s, and the render
// of its answers.
class OrdersSolve {
 public:
  OrdersSolve(const AtmosphereModel& model, const orders::OrdersSettings& s, double observer_altitude_m, bool segments,
              const ProgressFn& progress)
      : m_(model), s_(s) {
    ss_scaled_ = s_.ss_scaled && s_.max_orders >= 2;
    md_ = orders::PrepareMedium(m_, s_, ss_scaled_ && s_.ss_scaled_view > 0);
    sun_ = orders::BuildSunTables(m_, md_, s_);
    nodes_ = orders::BuildNodes(m_, s_, observer_altitude_m);
    res_ = orders::SolveMultipleScattering(m_, md_, sun_, nodes_, s_, segments, progress);
  }

  // The resolved settings, one "key: value" line each, every key prefixed by `prefix`.
  std::string Describe(const std::string& prefix) const {
    return fmt::format(
        "{0}radius_nodes: {1}\n{0}view_nodes: {2} up + {3} down per altitude\n{0}azimuth_nodes: {4}\n"
        "{0}sun_nodes: {5}\n{0}ray_steps: {6}\n{0}view_steps: {7}\n{0}truncation_deg: {8}\n{0}kernel: {9}\n{0}orders_computed: {10}\n"
        "{0}tail_extrapolated: {11}{15}\n{0}last_order_fraction: {12:.3g}\n{0}tolerance: {13}\n{0}single_scattering_attenuation: {14}\n"
        "{0}wavelength_batches: {16}\n{0}acceleration: {17}\n",
        prefix, nodes_.radius.size(), s_.nup, s_.ndn, s_.nphi, SunNodesText(), s_.nt, s_.nss, md_.ConesText(),
        s_.kernel_sub > 0 ? fmt::format("basis-integrated, {} sub-intervals", s_.kernel_sub) : std::string("phase at the nodes"),
        res_.orders_done, res_.tail != orders::Tail::kNone ? "true" : "false", res_.last_fraction, s_.tolerance, ss_scaled_ ? "delta-scaled" : "unscaled",
        res_.tail == orders::Tail::kDominant ? " (dominant mode)" : res_.tail == orders::Tail::kTwoModes ? " (two modes)" : "",
        res_.wavelength_batches, fmt::format("{} (scaled column optical depth {:.2f})", res_.accelerated ? "diffusion" : "none", res_.column_depth));
  }

  void Render(double observer_altitude_m, double sun_zenith_rad, const std::vector<std::array<double, 3>>& dirs,
              const ViewSegment* segment, std::vector<double>* out, std::vector<double>* single) const {
    orders::Render(orders::RenderInputs{&m_, &md_, &sun_, &nodes_, &s_, &res_, ss_scaled_, &cache_}, observer_altitude_m,
                   sun_zenith_rad, dirs, segment, out, single);
  }

 private:
  // The count, and the range when the sun nodes are cut to part of it (a split's part).
  std::string SunNodesText() const {
    const orders::OrdersSettings all = [&] {
      orders::OrdersSettings a = s_;
      a.sun_min_deg = 0.0, a.sun_max_deg = 180.0;
      return a;
    }();
    if (orders::SunNodes(all).size() == s_.sun_deg.size()) return fmt::format("{}", s_.sun_deg.size());
    return fmt::format("{} ({} to {} deg)", s_.sun_deg.size(), s_.sun_deg.front(), s_.sun_deg.back());
  }

  const AtmosphereModel& m_;
  orders::OrdersSettings s_;
  bool ss_scaled_ = false;  // s_.ss_scaled with multiple-scattering orders (max_orders >= 2)
  orders::Medium md_;
  orders::SunTables sun_;
  orders::Nodes nodes_;
  orders::SolveResult res_;
  mutable orders::ViewRayCache cache_;
};

class OrdersMethod : public SkyMethod {
 public:
  OrdersMethod(const AtmosphereModel& model, const SkyMethodOptions& options, const ProgressFn& progress)
      : s_(orders::SettingsFor(options)), segments_(options.segments) {
    if (s_.split_from_deg <= 0.0) {
      day_.emplace(model, s_, options.observer_altitude_m, segments_, progress);
      return;
    }
    const orders::SplitSettings parts = orders::SplitParts(s_);
    day_.emplace(model, parts.day, options.observer_altitude_m, segments_, progress);
    twilight_.emplace(model, parts.twilight, options.observer_altitude_m, segments_, progress);
  }

  std::string Name() const override { return "orders"; }

  std::string Describe() const override {
    if (!twilight_) return "method: orders\n" + day_->Describe("");
    return fmt::format(
               "method: orders\ntwilight_split: the daylight tables to sun zenith {} deg, the twilight tables ({} azimuths, "
               "medium's kernel and cones) beyond {} deg, blended between\n",
               s_.split_from_deg, s_.split_azimuths, s_.split_from_deg + s_.split_width_deg) +
           day_->Describe("") + twilight_->Describe("twilight_");
  }

  void Radiance(double observer_altitude_m, double sun_zenith_rad, const std::vector<std::array<double, 3>>& dirs,
                std::vector<double>* out) const override {
    Answer(observer_altitude_m, sun_zenith_rad, dirs, nullptr, out, nullptr);
  }
  // L_1 of the split L = L_1 + L_ms (the exact march of the output ray), computed beside L.
  bool SingleScatteringRadiance(double observer_altitude_m, double sun_zenith_rad, const std::vector<std::array<double, 3>>& dirs,
                                std::vector<double>* out) const override {
    std::vector<double> total;
    Answer(observer_altitude_m, sun_zenith_rad, dirs, nullptr, &total, out);
    return true;
  }
  // Segments need the sources kept by the solve (SkyMethodOptions::segments).
  bool SupportsSegments() const override { return segments_; }
  void SegmentRadiance(double observer_altitude_m, double sun_zenith_rad, const std::vector<std::array<double, 3>>& dirs,
                       const ViewSegment& segment, std::vector<double>* out) const override {
    if (!segments_) throw std::logic_error("orders: SegmentRadiance on a method built without SkyMethodOptions::segments");
    Answer(observer_altitude_m, sun_zenith_rad, dirs, &segment, out, nullptr);
  }

 private:
  // The daylight solve's answer, the twilight one's, or their blend in the zone between.
  void Answer(double observer_altitude_m, double sun_zenith_rad, const std::vector<std::array<double, 3>>& dirs,
              const ViewSegment* segment, std::vector<double>* out, std::vector<double>* single) const {
    const double w = twilight_ ? orders::TwilightWeight(s_, sun_zenith_rad) : 0.0;
    if (w < 1.0) day_->Render(observer_altitude_m, sun_zenith_rad, dirs, segment, out, single);
    if (w <= 0.0) return;
    if (w >= 1.0) {
      twilight_->Render(observer_altitude_m, sun_zenith_rad, dirs, segment, out, single);
      return;
    }
    std::vector<double> tw_out, tw_single;
    twilight_->Render(observer_altitude_m, sun_zenith_rad, dirs, segment, &tw_out, single != nullptr ? &tw_single : nullptr);
    orders::Blend(w, tw_out, out);
    if (single != nullptr) orders::Blend(w, tw_single, single);
  }

  orders::OrdersSettings s_;
  bool segments_ = false;
  std::optional<OrdersSolve> day_, twilight_;  // day_ alone without the split
};

}  // namespace

std::unique_ptr<SkyMethod> MakeOrdersMethod(const AtmosphereModel& model, const SkyMethodOptions& options,
                                            const ProgressFn& progress) {
  return std::make_unique<OrdersMethod>(model, options, progress);
}

}  // namespace skybake
