#include "follicle/image/image_io.hpp"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfMultiPartOutputFile.h>
#include <OpenEXR/ImfOutputPart.h>
#include <OpenEXR/ImfPartType.h>
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <cmath>
#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>

#include "follicle/core/atomic_file.hpp"
#include "follicle/core/error.hpp"
#include "testing/testing.hpp"

using namespace follicle;
using namespace follicle::image;

namespace {
ImageRGBA8 pattern_rgba(int w, int h) {
  ImageRGBA8 img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int c = 0; c < 4; ++c) img.at(x, y, c) = uint8_t((x * 37 + y * 11 + c * 73) & 255);
  return img;
}
void write_bytes(const std::filesystem::path& p, const std::string& s) {
  std::ofstream(p, std::ios::binary).write(s.data(), std::streamsize(s.size()));
}
}  // namespace

TEST(ImageIo, PngRgbaRoundTripIsExact) {
  auto dir = test::scratch_dir("png_rgba");
  const ImageRGBA8 img = pattern_rgba(37, 23);
  write_png(dir / "a.png", img);
  EXPECT_EQ(read_png_rgba(dir / "a.png"), img);
}

TEST(ImageIo, PngGrayRoundTripIsExactAndTopRowFirst) {
  auto dir = test::scratch_dir("png_gray");
  ImageGray8 img(5, 4);
  for (int y = 0; y < 4; ++y)
    for (int x = 0; x < 5; ++x) img.at(x, y) = uint8_t(y * 50 + x);
  write_png(dir / "g.png", img);
  const ImageGray8 back = read_png_gray(dir / "g.png");
  EXPECT_EQ(back, img);
  // A gray PNG read as RGBA replicates the value and sets alpha to 255.
  const ImageRGBA8 rgba = read_png_rgba(dir / "g.png");
  EXPECT_EQ(rgba.at(4, 3, 0), img.at(4, 3));
  EXPECT_EQ(rgba.at(4, 3, 2), img.at(4, 3));
  EXPECT_EQ(rgba.at(4, 3, 3), 255);
}

TEST(ImageIo, PngRgbRoundTrip) {
  auto dir = test::scratch_dir("png_rgb");
  ImageRGB8 img(3, 2);
  for (std::size_t i = 0; i < img.storage().size(); ++i) img.storage()[i] = uint8_t(i * 13);
  write_png(dir / "c.png", img);
  const ImageRGBA8 back = read_png_rgba(dir / "c.png");
  for (int y = 0; y < 2; ++y)
    for (int x = 0; x < 3; ++x)
      for (int c = 0; c < 3; ++c) EXPECT_EQ(back.at(x, y, c), img.at(x, y, c));
}

TEST(ImageIo, ExrGrayRoundTripIsBitExact) {
  auto dir = test::scratch_dir("exr_gray");
  ImageF img(17, 9);
  for (int y = 0; y < 9; ++y)
    for (int x = 0; x < 17; ++x) img.at(x, y) = std::ldexp(float(x - 8) / 3.f, y - 4) + 1e-7f * y;
  img.at(0, 0) = std::numeric_limits<float>::denorm_min();
  img.at(1, 0) = -0.0f;
  write_exr(dir / "h.exr", img);
  const ImageF back = read_exr_gray(dir / "h.exr");
  ASSERT_EQ(back.width(), 17);
  ASSERT_EQ(back.height(), 9);
  EXPECT_EQ(std::memcmp(back.data(), img.data(), img.storage().size() * sizeof(float)), 0);
}

TEST(ImageIo, ExrRgbAndRgbaRoundTrip) {
  auto dir = test::scratch_dir("exr_rgba");
  ImageRGBAF a(6, 5);
  ImageRGBF b(6, 5);
  for (std::size_t i = 0; i < a.storage().size(); ++i) a.storage()[i] = float(i) * 0.123f - 2.f;
  for (std::size_t i = 0; i < b.storage().size(); ++i) b.storage()[i] = float(i) * -0.77f;
  write_exr(dir / "a.exr", a);
  write_exr(dir / "b.exr", b);
  EXPECT_EQ(read_exr_rgba(dir / "a.exr"), a);
  const ImageRGBAF bb = read_exr_rgba(dir / "b.exr");
  for (int y = 0; y < 5; ++y)
    for (int x = 0; x < 6; ++x) {
      for (int c = 0; c < 3; ++c) EXPECT_EQ(bb.at(x, y, c), b.at(x, y, c));
      EXPECT_EQ(bb.at(x, y, 3), 1.0f);  // missing alpha reads as opaque
    }
}

TEST(ImageIo, MissingFileIsError) {
  auto dir = test::scratch_dir("missing");
  EXPECT_THROW(read_png_rgba(dir / "nope.png"), Error);
  EXPECT_THROW(read_exr_gray(dir / "nope.exr"), Error);
}

TEST(ImageIo, EmptyGarbageAndTruncatedPngAreErrors) {
  auto dir = test::scratch_dir("bad_png");
  write_bytes(dir / "empty.png", "");
  EXPECT_THROW(read_png_rgba(dir / "empty.png"), Error);
  std::string garbage;
  for (int i = 0; i < 1000; ++i) garbage.push_back(char((i * 7919 + 13) & 255));
  write_bytes(dir / "garbage.png", garbage);
  EXPECT_THROW(read_png_rgba(dir / "garbage.png"), Error);
  write_png(dir / "good.png", pattern_rgba(64, 64));
  const std::string full = read_file(dir / "good.png");
  for (std::size_t keep : {std::size_t(8), std::size_t(40), full.size() / 2, full.size() - 20}) {
    write_bytes(dir / "trunc.png", full.substr(0, keep));
    EXPECT_THROW(read_png_rgba(dir / "trunc.png"), Error) << "kept " << keep << " bytes";
  }
}

TEST(ImageIo, GarbageAndTruncatedExrAreErrors) {
  auto dir = test::scratch_dir("bad_exr");
  std::string garbage;
  for (int i = 0; i < 1000; ++i) garbage.push_back(char((i * 131 + 7) & 255));
  write_bytes(dir / "garbage.exr", garbage);
  EXPECT_THROW(read_exr_gray(dir / "garbage.exr"), Error);
  write_bytes(dir / "empty.exr", "");
  EXPECT_THROW(read_exr_rgba(dir / "empty.exr"), Error);
  ImageF img(64, 64, 0.5f);
  write_exr(dir / "good.exr", img);
  const std::string full = read_file(dir / "good.exr");
  for (std::size_t keep : {std::size_t(10), std::size_t(200), full.size() / 2, full.size() - 10}) {
    write_bytes(dir / "trunc.exr", full.substr(0, keep));
    EXPECT_THROW(read_exr_gray(dir / "trunc.exr"), Error) << "kept " << keep << " bytes";
  }
}

TEST(ImageIo, WritingEmptyImageIsErrorAndLeavesNoFile) {
  auto dir = test::scratch_dir("empty_write");
  EXPECT_THROW(write_png(dir / "e.png", ImageRGBA8{}), Error);
  EXPECT_THROW(write_exr(dir / "e.exr", ImageF{}), Error);
  EXPECT_FALSE(std::filesystem::exists(dir / "e.png"));
  EXPECT_FALSE(std::filesystem::exists(dir / "e.exr"));
}

namespace {

// Lowers the file-size limit (RLIMIT_FSIZE) so writes past `bytes` fail with EFBIG, like a disk
// that fills up; SIGXFSZ is ignored so the write returns the error instead of killing the test.
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    getrlimit(RLIMIT_FSIZE, &m_old);
    m_old_handler = std::signal(SIGXFSZ, SIG_IGN);
    rlimit lim = m_old;
    lim.rlim_cur = bytes;
    setrlimit(RLIMIT_FSIZE, &lim);
  }
  ~FileSizeLimit() {
    setrlimit(RLIMIT_FSIZE, &m_old);
    std::signal(SIGXFSZ, m_old_handler);
  }

 private:
  rlimit m_old{};
  void (*m_old_handler)(int) = nullptr;
};

}  // namespace

TEST(ImageIO, AWriteThatRunsOutOfSpaceFailsNamingThePathAndLeavesNoFile) {
  // Regression: on a full disk `follicle render` printed "wrote ..." and left a PNG without its
  // end chunk (stbi_write_png ignored fwrite errors).
  const auto dir = test::scratch_dir("png_full_disk");
  const auto file = dir / "noise.png";
  ImageRGBA8 img(256, 256);
  uint32_t x = 12345;
  for (auto& v : img.storage())
    v = uint8_t((x = x * 1664525u + 1013904223u) >> 24);  // incompressible
  std::string message;
  {
    const FileSizeLimit limit(4096);
    try {
      write_png(file, img);
    } catch (const Error& e) {
      message = e.what();
    }
  }
  ASSERT_FALSE(message.empty()) << "a write past the size limit was reported as success";
  EXPECT_NE(message.find(file.string()), std::string::npos) << message;
  EXPECT_EQ(message.find(".tmp-"), std::string::npos) << message;  // not the temporary name
  EXPECT_NE(message.find("write failed: File too large"), std::string::npos) << message;
  for (const auto& e : std::filesystem::directory_iterator(dir))
    ADD_FAILURE() << "left behind: " << e.path();
  // Without the limit the same image is written and reads back.
  write_png(file, img);
  EXPECT_EQ(read_png_rgba(file).storage(), img.storage());
}

// Reproducers of the fuzzing campaign (fuzz/regressions/, docs/reliability.md): each is refused
// with follicle::Error naming the file, before the library that misbehaved sees it.
TEST(ImageIOFuzzRegressions, AJpegHuffmanTableWithTooManyCodesIsRefusedBeforeStb) {
  // Before: stb_image wrote past its Huffman size table (ASan: heap-buffer-overflow).
  const auto f = test::source_dir() / "fuzz/regressions/png/stb_jpeg_huffman_count_overflow.jpg";
  try {
    (void)read_png_rgba(f);
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("a Huffman table declares"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find(f.string()), std::string::npos) << e.what();
  }
}

TEST(ImageIOFuzzRegressions, AnExrAttributeLargerThanTheFileIsRefusedAtOnce) {
  // Before: OpenEXR allocated the declared size first; these 44-byte files took 10-33 s.
  for (const char* name : {"slow_read.exr", "slow_read_2.exr"}) {
    const auto f = test::source_dir() / "fuzz/regressions/exr" / name;
    EXPECT_THROW((void)read_exr_rgba(f), Error) << name;
  }
  // A real EXR still reads.
  const auto dir = test::scratch_dir("exr_ok");
  ImageRGBAF img(3, 2);
  for (auto& v : img.storage()) v = 0.5f;
  write_exr(dir / "ok.exr", img);
  EXPECT_EQ(read_exr_rgba(dir / "ok.exr").width(), 3);
}

namespace {
// Overwrites the dataWindow box of an EXR written by write_exr with (0, 0)-(w-1, h-1).
std::string with_exr_data_window(std::string b, int32_t w, int32_t h) {
  const std::string key = std::string("dataWindow") + '\0' + "box2i" + '\0';
  const std::size_t at = b.find(key);
  if (at == std::string::npos) return {};
  const std::size_t box = at + key.size() + 4;  // after the 4-byte attribute size
  const int32_t v[4] = {0, 0, w - 1, h - 1};
  std::memcpy(b.data() + box, v, sizeof v);
  return b;
}
}  // namespace

TEST(ImageIOResourceGuards, AnExrDeclaringHugePixelsIsRefusedBeforeAllocating) {
  // Before: a 3x2 file claiming 40000x40000 made the reader allocate 25.6 GB of floats.
  const auto dir = test::scratch_dir("exr_huge");
  ImageRGBAF img(3, 2);
  for (auto& v : img.storage()) v = 0.25f;
  write_exr(dir / "small.exr", img);
  const std::string huge = with_exr_data_window(read_file(dir / "small.exr"), 40000, 40000);
  ASSERT_FALSE(huge.empty());
  write_bytes(dir / "huge.exr", huge);
  for (int gray = 0; gray < 2; ++gray) {
    try {
      if (gray) {
        (void)read_exr_gray(dir / "huge.exr");
      } else {
        (void)read_exr_rgba(dir / "huge.exr");
      }
      FAIL() << "accepted";
    } catch (const Error& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find("40000x40000"), std::string::npos) << msg;
      EXPECT_NE(msg.find("at most 268 M pixels"), std::string::npos) << msg;
      EXPECT_NE(msg.find("huge.exr"), std::string::npos) << msg;
    }
  }
  // The unchanged file still reads.
  EXPECT_EQ(read_exr_rgba(dir / "small.exr").width(), 3);
}

TEST(ImageIOResourceGuards, APngDeclaringHugePixelsIsRefusedBeforeDecoding) {
  // A PNG header (IHDR) of 20000 x 20000 grey with no image data. (stb refuses RGBA above
  // 2^28 pixels itself, "too large"; a grey image it would decode up to 2^30 pixels.)
  auto be32 = [](uint32_t v) {
    return std::string{char(v >> 24), char(v >> 16), char(v >> 8), char(v)};
  };
  std::string png = "\x89PNG\r\n\x1a\n";
  png += be32(13) + "IHDR" + be32(20000) + be32(20000) + std::string("\x08\x00\x00\x00\x00", 5);
  png += be32(0);  // CRC (stb does not check it)
  png += be32(0) + "IEND" + be32(0);
  const auto dir = test::scratch_dir("png_huge");
  write_bytes(dir / "huge.png", png);
  try {
    (void)read_png_rgba(dir / "huge.png");
    FAIL() << "accepted";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("PNG/JPEG image is 20000x20000 (400 M pixels); Follicle reads images of at "
                       "most 268 M pixels"),
              std::string::npos)
        << msg;
  }
}

TEST(ImageIOFuzzRegressions, OnlyPngAndJpegAreDecodedSoATgaBombIsRefusedAtOnce) {
  // Before: stb took these 120 bytes for an RLE TGA of 65496 x 224 pixels and decoded for
  // seconds (under ASan 5-11 s). Follicle documents PNG and JPEG only.
  const auto f = test::source_dir() / "fuzz/regressions/png/tga_decompression_bomb.bin";
  try {
    (void)read_png_rgba(f);
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("not a PNG or JPEG file"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)read_gray_map(f), Error);
}

TEST(ImageIOFuzzRegressions, AnExrDeclaringMorePixelsThanAnyCompressionCouldHoldIsRefused) {
  // Before: 268 bytes declaring 16383753 x 7 pixels had 1.8 GB allocated and zeroed (libFuzzer:
  // out of memory) before OpenEXR found no data.
  const auto f = test::source_dir() / "fuzz/regressions/exr/window_larger_than_any_compression.exr";
  try {
    (void)read_exr_rgba(f);
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("EXR declares 16383753x7 pixels but holds only 268 bytes"),
              std::string::npos)
        << e.what();
  }
}

TEST(ImageIOFuzzRegressions, AMultiPartExrHasEveryHeaderChecked) {
  // Before: multi-part headers were left to OpenEXR; this 177-byte file took 20 s and gigabytes.
  const auto f = test::source_dir() / "fuzz/regressions/exr/multipart_attribute_size.exr";
  try {
    (void)read_exr_rgba(f);
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("declares 1851877465 bytes but the file has 144 left"),
              std::string::npos)
        << e.what();
  }
  // A valid two-part file (written by OpenEXR) still reads: its first part.
  const auto dir = test::scratch_dir("exr_multipart");
  const auto ok = dir / "two_parts.exr";
  {
    std::vector<Imf::Header> headers;
    for (const char* name : {"first", "second"}) {
      Imf::Header h(3, 2);
      h.channels().insert("Y", Imf::Channel(Imf::FLOAT));
      h.setName(name);
      h.setType(Imf::SCANLINEIMAGE);
      headers.push_back(h);
    }
    Imf::MultiPartOutputFile file(ok.c_str(), headers.data(), int(headers.size()));
    std::vector<float> px(6, 0.75f);
    for (int part = 0; part < 2; ++part) {
      Imf::OutputPart out(file, part);
      Imf::FrameBuffer fb;
      fb.insert("Y", Imf::Slice(Imf::FLOAT, (char*)px.data(), sizeof(float), 3 * sizeof(float)));
      out.setFrameBuffer(fb);
      out.writePixels(2);
    }
  }
  const ImageF g = read_exr_gray(ok);
  ASSERT_EQ(g.width(), 3);
  EXPECT_FLOAT_EQ(g.at(2, 1), 0.75f);
}

TEST(ImageIOFuzzRegressions, AnExrWithoutItsLineOffsetsIsRefusedBeforeThePixelsAreAllocated) {
  // Before: 132 bytes declaring a large window had gigabytes zeroed before isComplete() said no.
  const auto f = test::source_dir() / "fuzz/regressions/exr/window_without_offsets.exr";
  try {
    (void)read_exr_rgba(f);
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(f.string()), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)read_exr_gray(f), Error);
  // The header checks keep every valid file of the seed corpus (compressions none, RLE, ZIPS,
  // ZIP, PIZ, PXR24, B44, a tiled file; half, float and uint channels) readable.
  int n = 0;
  for (const auto& e :
       std::filesystem::directory_iterator(test::source_dir() / "fuzz/corpus/exr")) {
    EXPECT_NO_THROW((void)read_exr_rgba(e.path())) << e.path();
    ++n;
  }
  EXPECT_GE(n, 7);
}
