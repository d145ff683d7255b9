// Hash-based lattice value noise and per-pixel random numbers: reproducible on every machine and
// independent of thread scheduling (a value depends only on its coordinates and key).
#pragma once

#include <cmath>
#include <cstdint>

namespace fieldrig::sim::detail {

inline std::uint64_t mix64(std::uint64_t h) {
  h ^= h >> 33;
  h *= 0xFF51AFD7ED558CCDULL;
  h ^= h >> 33;
  h *= 0xC4CEB9FE1A85EC53ULL;
  h ^= h >> 33;
  return h;
}

// A value in [0, 1) for an integer lattice point.
inline float latticeValue(std::int64_t i, std::int64_t j, std::int64_t k) {
  std::uint64_t h = static_cast<std::uint64_t>(i) * 0x9E3779B97F4A7C15ULL ^
                    static_cast<std::uint64_t>(j) * 0xC2B2AE3D27D4EB4FULL ^
                    static_cast<std::uint64_t>(k) * 0x165667B19E3779F9ULL;
  h ^= h >> 31;
  h *= 0xD6E8FEB86659FD93ULL;
  h ^= h >> 32;
  return static_cast<float>(h >> 40) * (1.0F / 16777216.0F);
}

// Trilinear value noise in [0, 1) with a smooth (cubic) blend between lattice points.
inline float valueNoise(float x, float y, float z) {
  const float fx = std::floor(x);
  const float fy = std::floor(y);
  const float fz = std::floor(z);
  float tx = x - fx;
  float ty = y - fy;
  float tz = z - fz;
  tx = tx * tx * (3.0F - 2.0F * tx);
  ty = ty * ty * (3.0F - 2.0F * ty);
  tz = tz * tz * (3.0F - 2.0F * tz);
  const auto i = static_cast<std::int64_t>(fx);
  const auto j = static_cast<std::int64_t>(fy);
  const auto k = static_cast<std::int64_t>(fz);
  const float c000 = latticeValue(i, j, k);
  const float c100 = latticeValue(i + 1, j, k);
  const float c010 = latticeValue(i, j + 1, k);
  const float c110 = latticeValue(i + 1, j + 1, k);
  const float c001 = latticeValue(i, j, k + 1);
  const float c101 = latticeValue(i + 1, j, k + 1);
  const float c011 = latticeValue(i, j + 1, k + 1);
  const float c111 = latticeValue(i + 1, j + 1, k + 1);
  const float x00 = c000 + tx * (c100 - c000);
  const float x10 = c010 + tx * (c110 - c010);
  const float x01 = c001 + tx * (c101 - c001);
  const float x11 = c011 + tx * (c111 - c011);
  const float y0 = x00 + ty * (x10 - x00);
  const float y1 = x01 + ty * (x11 - x01);
  return y0 + tz * (y1 - y0);
}

// Two independent standard normal values from a key (Box–Muller on a hashed pair).
inline void gaussianPair(std::uint64_t key, float& a, float& b) {
  const std::uint64_t h = mix64(key);
  const double u1 = (static_cast<double>(h >> 40) + 0.5) * (1.0 / 16777216.0);
  const double u2 = static_cast<double>((h >> 16) & 0xFFFFFFULL) * (1.0 / 16777216.0);
  const double r = std::sqrt(-2.0 * std::log(u1));
  a = static_cast<float>(r * std::cos(6.283185307179586 * u2));
  b = static_cast<float>(r * std::sin(6.283185307179586 * u2));
}

// Texture noise for shading: value noise on a lattice hashed through a fixed permutation table
// (Perlin's construction), a few table reads per corner instead of a 64-bit hash. Periodic every
// 256 cells (1 m at the leaves' 4 mm), far beyond any disparity range the rig searches.
class TextureNoise {
 public:
  TextureNoise() {
    // A fixed permutation from a fixed key: the same table on every machine.
    for (int i = 0; i < 256; ++i)
      perm_[i] = static_cast<std::uint8_t>(i);
    std::uint64_t state = 0x243F6A8885A308D3ULL;
    for (int i = 255; i > 0; --i) {
      state = mix64(state + 0x9E3779B97F4A7C15ULL);
      const int j = static_cast<int>(state % static_cast<std::uint64_t>(i + 1));
      const std::uint8_t t = perm_[i];
      perm_[i] = perm_[j];
      perm_[j] = t;
    }
    for (int i = 0; i < 256; ++i)
      perm_[256 + i] = perm_[i];
  }

  // In [0, 1), smooth (cubic blend) between lattice points.
  float operator()(float x, float y, float z) const {
    const float fx = std::floor(x);
    const float fy = std::floor(y);
    const float fz = std::floor(z);
    float tx = x - fx;
    float ty = y - fy;
    float tz = z - fz;
    tx = tx * tx * (3.0F - 2.0F * tx);
    ty = ty * ty * (3.0F - 2.0F * ty);
    tz = tz * tz * (3.0F - 2.0F * tz);
    const int i = static_cast<int>(static_cast<std::int64_t>(fx) & 255);
    const int j = static_cast<int>(static_cast<std::int64_t>(fy) & 255);
    const int k = static_cast<int>(static_cast<std::int64_t>(fz) & 255);
    const int a = perm_[i] + j;
    const int b = perm_[i + 1] + j;
    const int aa = perm_[a] + k;
    const int ab = perm_[a + 1] + k;
    const int ba = perm_[b] + k;
    const int bb = perm_[b + 1] + k;
    constexpr float kScale = 1.0F / 256.0F;
    const float c000 = perm_[aa] * kScale;
    const float c100 = perm_[ba] * kScale;
    const float c010 = perm_[ab] * kScale;
    const float c110 = perm_[bb] * kScale;
    const float c001 = perm_[aa + 1] * kScale;
    const float c101 = perm_[ba + 1] * kScale;
    const float c011 = perm_[ab + 1] * kScale;
    const float c111 = perm_[bb + 1] * kScale;
    const float x00 = c000 + tx * (c100 - c000);
    const float x10 = c010 + tx * (c110 - c010);
    const float x01 = c001 + tx * (c101 - c001);
    const float x11 = c011 + tx * (c111 - c011);
    const float y0 = x00 + ty * (x10 - x00);
    const float y1 = x01 + ty * (x11 - x01);
    return y0 + tz * (y1 - y0);
  }

 private:
  std::uint8_t perm_[512 + 2]{};
};

// A standard normal value from a key, approximated by the sum of four uniform values (Irwin–Hall,
// rescaled; tails end at 3.46 sigma): sensor noise without log and cos per pixel.
inline float gaussianApprox(std::uint64_t key) {
  const std::uint64_t h = mix64(key);
  const float sum = static_cast<float>(h & 0xFFFF) + static_cast<float>((h >> 16) & 0xFFFF) +
                    static_cast<float>((h >> 32) & 0xFFFF) + static_cast<float>(h >> 48);
  return (sum * (1.0F / 65536.0F) - 2.0F) * 1.7320508F;
}

}  // namespace fieldrig::sim::detail
