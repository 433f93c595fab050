// Seeded, stateless hashing: the only source of randomness of the noise module.
//
// Every random quantity (a lattice gradient, a Worley feature point) is a pure function of
// (seed, stream, integer coordinates), so a value never depends on evaluation order or thread
// count (docs/developing.md rule 8) and any point of an infinite domain can be evaluated alone.
//
// Mixer: SplitMix64's finaliser (Steele, Lea & Flood 2014, "Fast splittable pseudorandom number
// generators", OOPSLA; the constants of java.util.SplittableRandom), an invertible 64-bit mix with
// full avalanche. Coordinates are folded in one at a time, each followed by a mix, so
// (1, 2) and (2, 1) hash differently.
#pragma once

#include <cstdint>

namespace skybake::noise {

// SplitMix64 finaliser: z ^= z >> 30; z *= 0xbf58476d1ce4e5b9; z ^= z >> 27; z *= 0x94d049bb133111eb;
// z ^= z >> 31 (after adding the golden-ratio increment 0x9e3779b97f4a7c15).
constexpr uint64_t Mix64(uint64_t z) {
  z += 0x9E3779B97F4A7C15ull;
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// Hash of a key and integer coordinates.
constexpr uint64_t Hash(uint64_t key, int64_t a) { return Mix64(key ^ Mix64(static_cast<uint64_t>(a))); }
constexpr uint64_t Hash(uint64_t key, int64_t a, int64_t b) { return Hash(Hash(key, a), b); }
constexpr uint64_t Hash(uint64_t key, int64_t a, int64_t b, int64_t c) { return Hash(Hash(key, a, b), c); }

// A key for an independent stream: (seed, stream id, sub-stream), e.g. (volume seed, channel,
// octave). Different streams give statistically independent fields.
constexpr uint64_t StreamKey(uint64_t seed, uint64_t stream, uint64_t sub = 0) {
  return Mix64(Mix64(seed ^ 0x5EEDC10D5EEDC10Dull) ^ Mix64(stream * 0x100000001B3ull + sub));
}

// The top 24 bits as a float uniform on [0, 1) (exact: multiples of 2^-24).
constexpr float UnitFloat(uint64_t h) { return static_cast<float>(h >> 40) * (1.0f / 16777216.0f); }
// The top 53 bits as a double uniform on [0, 1).
constexpr double UnitDouble(uint64_t h) { return static_cast<double>(h >> 11) * (1.0 / 9007199254740992.0); }

}  // namespace skybake::noise
