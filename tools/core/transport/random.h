// Deterministic random numbers for Monte-Carlo transport.
//
// Every estimate draws from its own stream, identified by (seed, stream id, sample index), so a
// texel's result does not depend on which thread computes it or in what order: outputs are
// byte-identical at any thread count (docs/developing.md rule 8).
//
// Generator: PCG32 (M. E. O'Neill, "PCG: A Family of Simple Fast Space-Efficient Statistically
// Good Algorithms for Random Number Generation", HMC-CS-2014-0905, 2014): 64-bit LCG state with
// the XSH-RR output function; the stream (increment) and initial state are derived from the
// identifiers by SplitMix64 (Steele, Lea & Flood 2014) to decorrelate neighbouring ids.
#pragma once

#include <cstdint>

namespace skybake {

inline uint64_t SplitMix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

class Pcg32 {
 public:
  Pcg32(uint64_t seed, uint64_t stream, uint64_t index) {
    inc_ = (SplitMix64(stream ^ SplitMix64(seed)) << 1u) | 1u;
    state_ = 0;
    Next();
    state_ += SplitMix64(index + 0x632BE59BD9B4E019ull * seed);
    Next();
  }
  uint32_t Next() {
    const uint64_t old = state_;
    state_ = old * 6364136223846793005ull + inc_;
    const uint32_t xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
    const uint32_t rot = static_cast<uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((-rot) & 31u));
  }
  // Uniform double in [0, 1) with 53 random bits.
  double Uniform() {
    const uint64_t hi = Next(), lo = Next();
    return static_cast<double>(((hi << 32) | lo) >> 11) * 0x1.0p-53;
  }

 private:
  uint64_t state_;
  uint64_t inc_;
};

}  // namespace skybake
