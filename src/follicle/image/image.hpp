#pragma once
// Image<T, C>: a row-major, interleaved image with C channels of type T. Row 0 is the top row.
#include <cstdint>
#include <vector>

#include "follicle/core/error.hpp"

namespace follicle::image {

template <class T, int C>
class Image {
 public:
  static constexpr int kChannels = C;
  using value_type = T;

  Image() = default;
  Image(int width, int height, T fill = T{}) { resize(width, height, fill); }

  void resize(int width, int height, T fill = T{}) {
    if (width < 0 || height < 0) fail("image size {}x{} is negative", width, height);
    m_w = width;
    m_h = height;
    m_data.assign(std::size_t(width) * std::size_t(height) * C, fill);
  }
  int width() const { return m_w; }
  int height() const { return m_h; }
  bool empty() const { return m_data.empty(); }
  std::size_t num_pixels() const { return std::size_t(m_w) * std::size_t(m_h); }

  T& at(int x, int y, int c = 0) { return m_data[(std::size_t(y) * m_w + x) * C + c]; }
  const T& at(int x, int y, int c = 0) const { return m_data[(std::size_t(y) * m_w + x) * C + c]; }
  T* pixel(int x, int y) { return &m_data[(std::size_t(y) * m_w + x) * C]; }
  const T* pixel(int x, int y) const { return &m_data[(std::size_t(y) * m_w + x) * C]; }
  T* data() { return m_data.data(); }
  const T* data() const { return m_data.data(); }
  std::vector<T>& storage() { return m_data; }
  const std::vector<T>& storage() const { return m_data; }

  bool operator==(const Image& o) const {
    return m_w == o.m_w && m_h == o.m_h && m_data == o.m_data;
  }

 private:
  int m_w = 0, m_h = 0;
  std::vector<T> m_data;
};

using ImageRGBA8 = Image<uint8_t, 4>;
using ImageRGB8 = Image<uint8_t, 3>;
using ImageGray8 = Image<uint8_t, 1>;
using ImageF = Image<float, 1>;
using ImageRGBF = Image<float, 3>;
using ImageRGBAF = Image<float, 4>;

}  // namespace follicle::image
