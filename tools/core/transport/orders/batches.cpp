// The solve of `orders` in wavelength batches (solve.h): each batch's medium, sun tables and
// nodes sliced to its wavelengths, solved by SolveOrders, its own wavelengths copied into the
// whole result.
#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

#include "transport/orders/kernel.h"
#include "transport/orders/solve.h"

namespace skybake::orders {

namespace {

// The solve's tables per wavelength (bytes): with kept sources L, J, L_next and J_ms (float) and
// the ratio codes (one byte) per cell; without, L and J (L_n is transported in place, solve.cpp's
// OrderTables, and the observer's slabs are a radius node's share); and the kernels.
size_t TableBytesPerWavelength(const Nodes& nodes, const OrdersSettings& s, bool keep_sources) {
  const size_t cells = nodes.radius.size() * nodes.ns * nodes.nu * static_cast<size_t>(s.nphi);
  const size_t per_cell = keep_sources ? 4 * sizeof(float) + sizeof(uint8_t) : 2 * sizeof(float);
  return cells * per_cell + KernelBytesPerWavelength(nodes, s);
}

}  // namespace

size_t BatchSize(size_t nw, size_t fit) {
  if (fit >= nw || nw <= 2) return nw;
  // A multiple of 8 where 8 fit: the solve's products run 8 wavelengths wide (simd.h), and a
  // batch's rows of J are then whole vectors (16 floats: one cache line per corner of the
  // gather). Measured on cloudy4's LUT (25 wavelengths): batches of 16 and 10 257 s, of 13 and 13
  // 346 s, one solve 171 s.
  size_t size = std::max<size_t>(2, fit >= 8 ? fit / 8 * 8 : fit);
  // As few batches as that size needs, the wavelengths shared evenly among them (each batch but
  // the reference's also solves the reference), rounded up to a multiple of 8: a last batch of a
  // wavelength or two would cost a whole pass of the orders (an order costs nearly the same at 10
  // wavelengths as at 17: docs/sky-methods.md "Measured speed").
  const size_t batches = (nw - 1 + size - 2) / (size - 1);
  size_t even = (nw + batches - 1 + batches - 1) / batches;
  if (size >= 8) even = (even + 7) / 8 * 8;
  return std::min(size, even);
}

std::vector<WavelengthBatch> PlanWavelengthBatches(const Medium& md, const Nodes& nodes, const OrdersSettings& s, bool keep_sources) {
  const size_t nw = md.nw, per_w = TableBytesPerWavelength(nodes, s, keep_sources);
  const size_t per_batch = BatchSize(nw, (static_cast<size_t>(s.solve_tables_mib) << 20) / per_w);
  std::vector<WavelengthBatch> batches;
  for (size_t first = 0; first < nw;) {
    WavelengthBatch wb;
    wb.first = first;
    wb.end = std::min(nw, first + per_batch);
    if (md.wref < wb.first || md.wref >= wb.end) wb.end = std::min(nw, first + per_batch - 1);  // a place for the reference
    if (md.wref < wb.first) wb.solve.push_back(md.wref);
    for (size_t w = wb.first; w < wb.end; ++w) wb.solve.push_back(w);
    if (md.wref >= wb.end) wb.solve.push_back(md.wref);
    first = wb.end;
    batches.push_back(std::move(wb));
  }
  return batches;
}

SolveResult SolveMultipleScattering(const AtmosphereModel& m, const Medium& md, const SunTables& sun, const Nodes& nodes,
                                    const OrdersSettings& s, bool keep_sources, const ProgressFn& progress) {
  const std::vector<WavelengthBatch> batches = PlanWavelengthBatches(md, nodes, s, keep_sources);
  if (batches.size() == 1) return SolveOrders(m, md, sun, nodes, s, keep_sources, progress);
  const size_t nw = md.nw, per_w = TableBytesPerWavelength(nodes, s, keep_sources);
  size_t largest = 0;
  for (const WavelengthBatch& wb : batches) largest = std::max(largest, wb.solve.size());
  SolveResult out;
  out.wavelength_batches = batches.size();
  for (size_t b = 0; b < batches.size(); ++b) {
    const WavelengthBatch& wb = batches[b];
    // A smaller batch's tables leave memory under the largest one's peak: its step positions
    // take it, so that more radius nodes' positions are stored instead of computed every order
    // (the same bytes: MethodOrders.StoredAndComputedStepPositionsAreTheSameSky).
    OrdersSettings sb_settings = s;
    const size_t freed_mib = ((largest - wb.solve.size()) * per_w) >> 20;
    sb_settings.step_positions_mib = static_cast<int>(std::min<size_t>(4096, static_cast<size_t>(s.step_positions_mib) + freed_mib));
    const Medium mb = SliceMedium(md, wb.solve);
    const SunTables sb = SliceSunTables(sun, wb.solve);
    Nodes nb = nodes;
    nb.nw = wb.solve.size();
    const std::string stage = fmt::format("wavelengths {}-{} of {}: ", wb.first + 1, wb.end, nw);
    const ProgressFn batch_progress = [&](std::string_view what, double fraction) {
      ReportProgress(progress, stage + std::string(what), fraction);
    };
    const SolveResult r = SolveOrders(m, mb, sb, nb, sb_settings, keep_sources, batch_progress);
    if (b == 0) {
      out.orders_done = r.orders_done, out.tail = r.tail, out.last_fraction = r.last_fraction;
      out.accelerated = r.accelerated, out.column_depth = r.column_depth;
      out.ms.assign(r.ms.size() / nb.nw * nw, 0.0f);
      if (keep_sources) ZeroTable(&out.jms, r.jms.size() / nb.nw * nw);
    } else if (r.orders_done != out.orders_done || r.tail != out.tail) {
      throw std::logic_error("orders: wavelength batches stopped at different orders");  // they share the reference's decisions
    }
    auto put = [&](const auto& from, auto* to) {
      const size_t rows = from.size() / nb.nw;
      for (size_t i = 0; i < rows; ++i) {
        for (size_t j = 0; j < nb.nw; ++j) {
          const size_t w = wb.solve[j];
          if (w >= wb.first && w < wb.end) (*to)[i * nw + w] = from[i * nb.nw + j];
        }
      }
    };
    put(r.ms, &out.ms);
    if (keep_sources) put(r.jms, &out.jms);
  }
  return out;
}

}  // namespace skybake::orders
