// Multiple scattering by successive orders on the tables (Bruneton & Neyret 2008 §4): order 1 of
// the delta-scaled problem at every node, then per order the scattering step (kernel.h) and the
// transport step (transport.h), until the next order adds less than `tolerance` of the
// accumulated L_ms at the observer, or after `max_orders` (with a geometric tail once the ratio of
// successive orders has settled).
#pragma once

#include <vector>

#include "transport/orders/grid.h"
#include "transport/orders/medium.h"
#include "transport/orders/nodes.h"
#include "transport/orders/sun_tables.h"
#include "transport/sky_method.h"

namespace skybake::orders {

// How the series ended: by the tolerance or the cap without a tail, or with a geometric tail of
// one of three forms (solve.cpp: TakeTail, AddTail, SecondMode).
enum class Tail {
  kNone,
  kPerElement,  // each element's own ratio where it has settled, the observer's elsewhere
  kDominant,    // every element at its wavelength's observer ratio: the dominant mode's decay
  kTwoModes,    // the dominant mode's and the next one's
};

struct SolveResult {
  std::vector<float> ms;  // accumulated orders >= 2 at the observer radius: [(si*nu+k)*nphi+q]*nw
  // Accumulated multiple-scattering source J_ms* = sum_{n>=2} J_n at every node (cells x nw),
  // for view segments: L_seg,ms = int_0^t_end T* J_ms* dt; empty unless the solve keeps sources.
  Table jms;
  int orders_done = 0;
  Tail tail = Tail::kNone;
  double last_fraction = 0.0;
  size_t wavelength_batches = 1;  // SolveMultipleScattering's batches
  bool accelerated = false;       // with the diffusion correction (acceleration.h)
  double column_depth = 0.0;      // ScaledColumnDepth, which decides it
};

// One solve over every wavelength of md (sun and nodes at md's wavelengths); keep_sources:
// accumulate jms (view segments need it; the sky alone reads ms).
SolveResult SolveOrders(const AtmosphereModel& m, const Medium& md, const SunTables& sun, const Nodes& nodes, const OrdersSettings& s,
                        bool keep_sources, const ProgressFn& progress);

// The solve in wavelength batches (batches.cpp; docs/sky-methods.md "Peak memory"). The orders
// do not mix wavelengths, so a batch of wavelengths can be solved on its own, with tables sized to
// the batch: the solve's per-wavelength tables (the fields L, J and L_next, the ratio codes, the
// kernels, J_ms) are what grows with the wavelengths, and a thick cloud's 65 radius nodes make
// them 0.9 GB at 25 wavelengths. Each batch also solves the reference wavelength (Medium::wref),
// which every decision of the solve reads - the step placement, the stopping rule, the tail - so
// each batch takes the same steps and orders as the whole: the same bytes as one solve.
struct WavelengthBatch {
  std::vector<size_t> solve;  // the wavelengths solved (ascending; the reference among them)
  size_t first = 0, end = 0;  // the batch's own wavelengths [first, end), which it answers for
};
// The wavelengths solved per batch, of nw, where the tables of `fit` fit: nw when all do, else
// as many as fit rounded down to a multiple of 8 (at least 2, one of them the reference), then
// down to the fewest such batches' even share (rounded up to a multiple of 8): 25 of which 24 fit
// are batches of 16 and 9 with the reference, not 24 and 1.
size_t BatchSize(size_t nw, size_t fit);
// Batches of contiguous wavelengths whose tables fit in s.solve_tables_mib, BatchSize each.
std::vector<WavelengthBatch> PlanWavelengthBatches(const Medium& md, const Nodes& nodes, const OrdersSettings& s, bool keep_sources);

// SolveOrders over the batches of PlanWavelengthBatches, their results put together.
SolveResult SolveMultipleScattering(const AtmosphereModel& m, const Medium& md, const SunTables& sun, const Nodes& nodes,
                                    const OrdersSettings& s, bool keep_sources, const ProgressFn& progress);

}  // namespace skybake::orders
