#include "follicle/image/image_io.hpp"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfChromaticitiesAttribute.h>
#include <OpenEXR/ImfDoubleAttribute.h>
#include <OpenEXR/ImfFloatAttribute.h>
#include <OpenEXR/ImfFloatVectorAttribute.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfIntAttribute.h>
#include <OpenEXR/ImfKeyCodeAttribute.h>
#include <OpenEXR/ImfMatrixAttribute.h>
#include <OpenEXR/ImfMultiPartOutputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfOutputPart.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfRationalAttribute.h>
#include <OpenEXR/ImfStandardAttributes.h>
#include <OpenEXR/ImfStringAttribute.h>
#include <OpenEXR/ImfStringVectorAttribute.h>
#include <OpenEXR/ImfTimeCodeAttribute.h>
#include <OpenEXR/ImfVecAttribute.h>
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/resource.h>

// clang-format off
#include <cstdio>  // jpeglib.h needs FILE first
#include <jpeglib.h>
// clang-format on

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
TEST(ImageIOFuzzRegressions, JpegHuffmanTablesThatOverflowedStbAreRefused) {
  // Before: stb_image wrote past its Huffman size table (ASan: heap-buffer-overflow; UBSan:
  // index 257 out of bounds). The first file declares more than 256 codes in a DHT segment; the
  // second got past the marker walk that guarded stb, because stb resynchronises on stray bytes
  // between segments where the walk stopped. JPEG is now decoded by libjpeg-turbo.
  for (const char* name :
       {"stb_jpeg_huffman_count_overflow.jpg", "stb_jpeg_resync_huffman_overflow.jpg"}) {
    const auto f = test::source_dir() / "fuzz/regressions/png" / name;
    for (const bool gray : {false, true}) {
      try {
        if (gray)
          (void)read_png_gray(f);
        else
          (void)read_png_rgba(f);
        ADD_FAILURE() << name << " accepted";
      } catch (const Error& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find(f.string() + ": cannot decode JPEG: "), std::string::npos) << msg;
        EXPECT_NE(msg.find("Huffman"), std::string::npos) << msg;
      }
    }
  }
}

TEST(ImageIOFuzzRegressions, AnEmptyFirstIdatChunkNeverReachesStb) {
  // Before: stb computed nullptr + 0 for a zero-length first IDAT (UBSan: applying zero offset to
  // null pointer). The reproducer is a corrupt 10 x 2 PNG: refused, without undefined behaviour
  // (the sanitizer build of this test fails otherwise).
  const auto f = test::source_dir() / "fuzz/regressions/png/stb_empty_first_idat.png";
  EXPECT_THROW((void)read_png_rgba(f), Error);
  // A valid PNG with an empty IDAT chunk inserted before its data reads the same.
  const auto dir = test::scratch_dir("png_empty_idat");
  const ImageRGBA8 img = pattern_rgba(9, 7);
  write_png(dir / "a.png", img);
  const std::string bytes = read_file(dir / "a.png");
  const std::size_t idat = bytes.find("IDAT") - 4;
  const std::string empty("\0\0\0\0IDAT\x35\xaf\x06\x1e", 12);  // with its CRC
  write_bytes(dir / "b.png", bytes.substr(0, idat) + empty + bytes.substr(idat));
  EXPECT_EQ(read_png_rgba(dir / "b.png").storage(), img.storage());
}

TEST(ImageIOFuzzRegressions, APngChunkLargerThanTheFileIsRefusedBeforeStbAllocatesIt) {
  // Before: stb grew its IDAT buffer to the declared chunk length before reading it (164 bytes
  // declared 2 GB; libFuzzer: malloc(2147483648) out of memory).
  const auto f = test::source_dir() / "fuzz/regressions/png/stb_idat_larger_than_file.png";
  try {
    (void)read_png_rgba(f);
    FAIL() << "accepted";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("PNG chunk 'IDAT' at byte"), std::string::npos) << msg;
    EXPECT_NE(msg.find("(truncated?)"), std::string::npos) << msg;
  }
  // A valid PNG cut anywhere inside its chunks is refused naming the chunk; cut after its last
  // chunk's data (without IEND) it is still refused (by stb).
  const auto dir = test::scratch_dir("png_cut");
  write_png(dir / "a.png", pattern_rgba(9, 7));
  const std::string bytes = read_file(dir / "a.png");
  for (std::size_t cut = 9; cut + 12 < bytes.size(); cut += 7) {
    write_bytes(dir / "cut.png", bytes.substr(0, cut));
    EXPECT_THROW((void)read_png_rgba(dir / "cut.png"), Error) << "cut at " << cut;
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
    EXPECT_NE(msg.find("PNG image is 20000x20000 (400 M pixels); Follicle reads images of at "
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

TEST(ImageIOFuzzRegressions, AnExrDeclaringMorePixelsThanItsCompressionCouldHoldIsRefused) {
  // Before: 268 bytes declaring 16383753 x 7 pixels had 1.8 GB allocated and zeroed (libFuzzer:
  // out of memory) before OpenEXR found no data; 427 bytes declaring 16794118 x 2 pixels took
  // 2 s and 0.5 GB in release (a timeout under ASan) while the bound was 10,000:1 + 64 MB.
  for (const auto& [file, want] :
       {std::pair{"window_larger_than_any_compression.exr", "EXR declares 16383753x7 pixels"},
        std::pair{"window_beyond_zip_ratio.exr", "EXR declares 16794118x2 pixels"}}) {
    const auto f = test::source_dir() / "fuzz/regressions/exr" / file;
    try {
      (void)read_exr_rgba(f);
      ADD_FAILURE() << file << " accepted";
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(want), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("its compression packs at most"), std::string::npos)
          << e.what();
    }
  }
  // Real files at the edge read: a flat 1024 x 1024 half image in every compression OpenEXR
  // writes (the tightest packing each can reach), and a subsampled one.
  const auto dir = test::scratch_dir("exr_flat");
  for (const Imf::Compression c :
       {Imf::NO_COMPRESSION, Imf::RLE_COMPRESSION, Imf::ZIPS_COMPRESSION, Imf::ZIP_COMPRESSION,
        Imf::PIZ_COMPRESSION, Imf::PXR24_COMPRESSION, Imf::B44_COMPRESSION, Imf::B44A_COMPRESSION,
        Imf::DWAA_COMPRESSION, Imf::DWAB_COMPRESSION}) {
    const int n = 1024;
    Imf::Header header(n, n);
    header.compression() = c;
    header.channels().insert("Y", Imf::Channel(Imf::HALF));
    std::vector<Imath::half> px(std::size_t(n) * n, Imath::half(0.5f));
    Imf::FrameBuffer fb;
    fb.insert("Y", Imf::Slice(Imf::HALF, reinterpret_cast<char*>(px.data()), sizeof(Imath::half),
                              n * sizeof(Imath::half)));
    const auto f = dir / fmt::format("flat_{}.exr", int(c));
    {
      Imf::OutputFile out(f.c_str(), header);
      out.setFrameBuffer(fb);
      out.writePixels(n);
    }
    const auto size = std::filesystem::file_size(f);
    try {
      EXPECT_NEAR(read_exr_gray(f).at(n - 1, n - 1), 0.5f, 1e-3)  // DWA is lossy
          << "compression " << int(c) << ", " << size << " bytes";
    } catch (const Error& e) {
      ADD_FAILURE() << "compression " << int(c) << ", " << size << " bytes: " << e.what();
    }
  }
}

TEST(ImageIOFuzzRegressions, AnExrWindowOfTwoHugeSpansIsRefusedWithoutOverflow) {
  // Before: the pixel count 3587428055 x 2732673665 was formed in long long (UBSan: signed
  // integer overflow; in release it wrapped and could pass the limit).
  const auto f = test::source_dir() / "fuzz/regressions/exr/window_product_overflow.exr";
  try {
    (void)read_exr_rgba(f);
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("EXR image is 3587428055x2732673665"), std::string::npos)
        << e.what();
  }
}

TEST(ImageIOFuzzRegressions, AnExrChannelListEndingInsideANameIsRefused) {
  // Before: the channel-list check took a channel name left unfinished in the list's last byte
  // for the list's end; OpenEXR read on past the declared size, out of step with the header walk,
  // and resized a string attribute to 1.6 GB (10 s in release; libFuzzer: out of memory).
  const auto f = test::source_dir() / "fuzz/regressions/exr/chlist_unfinished_name.exr";
  try {
    (void)read_exr_gray(f);
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("EXR channel list declares 19 bytes"), std::string::npos)
        << e.what();
  }
}

TEST(ImageIOFuzzRegressions, ExrNamesLongerThanTheFlagsAllowAreRefusedAndLongNamesRead) {
  // OpenEXR reads a name of at most 31 characters (255 with the long-names flag, which its writer
  // sets when a name needs it); a longer one would be split and put it out of step.
  const auto dir = test::scratch_dir("exr_long_names");
  const std::string long_name(40, 'n');
  {
    Imf::Header header(2, 2);
    header.channels().insert("Y", Imf::Channel(Imf::FLOAT));
    header.insert(long_name, Imf::StringAttribute("value"));
    std::vector<float> px(4, 0.25f);
    Imf::FrameBuffer fb;
    fb.insert("Y", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(px.data()), sizeof(float),
                              2 * sizeof(float)));
    Imf::OutputFile out((dir / "long.exr").c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(2);
  }
  EXPECT_FLOAT_EQ(read_exr_gray(dir / "long.exr").at(1, 1), 0.25f);
  std::string bytes = read_file(dir / "long.exr");
  ASSERT_NE(uint8_t(bytes[5]) & 0x04, 0);  // the writer set the long-names flag
  bytes[5] = char(uint8_t(bytes[5]) & ~0x04);
  write_bytes(dir / "short.exr", bytes);
  try {
    (void)read_exr_gray(dir / "short.exr");
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("EXR attribute name at byte"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("is longer than 31 characters"), std::string::npos)
        << e.what();
  }
}

TEST(ImageIOFuzzRegressions, ExrAttributesMustHoldExactlyTheSizeOfTheirType) {
  // Before: a box2i dataWindow declaring 111 bytes; OpenEXR reads 16 and took the rest for new
  // attributes, one a 1.6 GB string (13 s in release; libFuzzer: out of memory).
  const auto f = test::source_dir() / "fuzz/regressions/exr/box_size_mismatch.exr";
  try {
    (void)read_exr_gray(f);
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(
        std::string(e.what()).find(
            "EXR attribute \"dataWindow\" of type box2i declares 111 bytes; that type has 16"),
        std::string::npos)
        << e.what();
  }
  // A file with attributes of many types, written by OpenEXR, reads; with one string of its
  // string vector longer than the vector it is refused.
  const auto dir = test::scratch_dir("exr_attribute_types");
  {
    Imf::Header header(2, 1);
    header.channels().insert("Y", Imf::Channel(Imf::FLOAT));
    header.insert("anInt", Imf::IntAttribute(7));
    header.insert("aFloat", Imf::FloatAttribute(0.5f));
    header.insert("aDouble", Imf::DoubleAttribute(0.25));
    header.insert("aV2f", Imf::V2fAttribute(Imath::V2f(1, 2)));
    header.insert("aV3i", Imf::V3iAttribute(Imath::V3i(1, 2, 3)));
    header.insert("aM44f", Imf::M44fAttribute(Imath::M44f()));
    header.insert("aRational", Imf::RationalAttribute(Imf::Rational(24, 1)));
    header.insert("aTimeCode", Imf::TimeCodeAttribute(Imf::TimeCode(1, 2, 3, 4)));
    header.insert("aKeyCode", Imf::KeyCodeAttribute(Imf::KeyCode()));
    header.insert("aChroma", Imf::ChromaticitiesAttribute(Imf::Chromaticities()));
    header.insert("floats", Imf::FloatVectorAttribute(std::vector<float>{1, 2, 3}));
    header.insert("names", Imf::StringVectorAttribute(std::vector<std::string>{"ab", "cde"}));
    std::vector<float> px = {0.125f, 0.75f};
    Imf::FrameBuffer fb;
    fb.insert("Y", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(px.data()), sizeof(float),
                              2 * sizeof(float)));
    Imf::OutputFile out((dir / "types.exr").c_str(), header);
    out.setFrameBuffer(fb);
    out.writePixels(1);
  }
  EXPECT_FLOAT_EQ(read_exr_gray(dir / "types.exr").at(1, 0), 0.75f);
  std::string bytes = read_file(dir / "types.exr");
  const std::size_t sv = bytes.find("stringvector");
  ASSERT_NE(sv, std::string::npos);
  bytes[sv + 13 + 4] = char(200);  // the first string's length: 2 -> 200
  write_bytes(dir / "bad_sv.exr", bytes);
  try {
    (void)read_exr_gray(dir / "bad_sv.exr");
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(
        std::string(e.what()).find("EXR string vector \"names\" holds a string that runs past its"),
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

// --- JPEG (libjpeg-turbo) -------------------------------------------------------------------

namespace {

// Encodes with libjpeg (default error handling: a failure here is a broken test, not input).
std::string encode_jpeg(const std::vector<uint8_t>& px, int w, int h, int comps, J_COLOR_SPACE cs,
                        bool progressive) {
  jpeg_compress_struct c{};
  jpeg_error_mgr err{};
  c.err = jpeg_std_error(&err);
  jpeg_create_compress(&c);
  unsigned char* buf = nullptr;
  unsigned long size = 0;
  jpeg_mem_dest(&c, &buf, &size);
  c.image_width = JDIMENSION(w);
  c.image_height = JDIMENSION(h);
  c.input_components = comps;
  c.in_color_space = cs;
  jpeg_set_defaults(&c);
  jpeg_set_quality(&c, 100, TRUE);
  for (int k = 0; k < c.num_components; ++k)  // no chroma subsampling: exact colours
    c.comp_info[k].h_samp_factor = c.comp_info[k].v_samp_factor = 1;
  if (progressive) jpeg_simple_progression(&c);
  jpeg_start_compress(&c, TRUE);
  for (int y = 0; y < h; ++y) {
    JSAMPROW row = const_cast<uint8_t*>(px.data()) + std::size_t(y) * std::size_t(w * comps);
    jpeg_write_scanlines(&c, &row, 1);
  }
  jpeg_finish_compress(&c);
  std::string out(reinterpret_cast<const char*>(buf), size);
  jpeg_destroy_compress(&c);
  std::free(buf);
  return out;
}

std::vector<uint8_t> smooth_rgb(int w, int h) {
  std::vector<uint8_t> px;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      px.push_back(uint8_t(40 + 150 * x / (w - 1)));
      px.push_back(uint8_t(200 - 120 * y / (h - 1)));
      px.push_back(uint8_t(90 + 60 * (x + y) / (w + h - 2)));
    }
  return px;
}

std::string jpeg_error(const std::filesystem::path& f, bool gray = false) {
  try {
    if (gray)
      (void)read_png_gray(f);
    else
      (void)read_png_rgba(f);
  } catch (const Error& e) {
    return e.what();
  }
  return "accepted";
}

}  // namespace

TEST(ImageIOJpeg, RgbGreyCmykAndProgressiveFilesDecodeToTheirPixels) {
  const auto dir = test::scratch_dir("jpeg_decode");
  const int w = 37, h = 23;
  const auto rgb = smooth_rgb(w, h);
  for (const bool progressive : {false, true}) {
    const auto f = dir / (progressive ? "p.jpg" : "b.jpg");
    write_bytes(f, encode_jpeg(rgb, w, h, 3, JCS_RGB, progressive));
    const ImageRGBA8 img = read_png_rgba(f);
    ASSERT_EQ(img.width(), w);
    ASSERT_EQ(img.height(), h);
    int worst = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        for (int k = 0; k < 4; ++k) {
          const int want = k < 3 ? rgb[std::size_t(3 * (y * w + x) + k)] : 255;
          worst = std::max(worst, std::abs(int(img.at(x, y, k)) - want));
        }
    EXPECT_LE(worst, 4) << (progressive ? "progressive" : "baseline");
    // The grey reading is the luma (Rec. 601) of the same pixels.
    const ImageGray8 g = read_png_gray(f);
    int worst_y = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        const auto* p = &rgb[std::size_t(3 * (y * w + x))];
        const double luma = 0.299 * p[0] + 0.587 * p[1] + 0.114 * p[2];
        worst_y = std::max(worst_y, int(std::lround(std::abs(g.at(x, y, 0) - luma))));
      }
    EXPECT_LE(worst_y, 4);
  }
  // A one-channel file.
  std::vector<uint8_t> grey;
  for (int i = 0; i < w * h; ++i) grey.push_back(uint8_t(10 + 7 * (i % 31)));
  write_bytes(dir / "g.jpg", encode_jpeg(grey, w, h, 1, JCS_GRAYSCALE, false));
  const ImageGray8 g = read_png_gray(dir / "g.jpg");
  const ImageRGBA8 g4 = read_png_rgba(dir / "g.jpg");
  int worst = 0;
  for (int i = 0; i < w * h; ++i) {
    worst = std::max(worst, std::abs(int(g.data()[i]) - grey[std::size_t(i)]));
    EXPECT_EQ(g4.data()[4 * i], g4.data()[4 * i + 2]);
  }
  EXPECT_LE(worst, 12);  // sharp steps every pixel: ringing at quality 100 stays small
  // CMYK as Photoshop writes it (Adobe marker, inverted values): red, and 50% black.
  std::vector<uint8_t> cmyk;
  for (int i = 0; i < 16 * 16; ++i) {
    const bool red = i % 16 < 8;
    const uint8_t ink[4] = {0, uint8_t(red ? 255 : 0), uint8_t(red ? 255 : 0),
                            uint8_t(red ? 0 : 128)};
    for (const uint8_t v : ink) cmyk.push_back(uint8_t(255 - v));
  }
  write_bytes(dir / "cmyk.jpg", encode_jpeg(cmyk, 16, 16, 4, JCS_CMYK, false));
  const ImageRGBA8 c = read_png_rgba(dir / "cmyk.jpg");
  EXPECT_NEAR(c.at(2, 5, 0), 255, 3);
  EXPECT_NEAR(c.at(2, 5, 1), 0, 3);
  EXPECT_NEAR(c.at(2, 5, 2), 0, 3);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(c.at(13, 5, k), 127, 3);
}

TEST(ImageIOJpeg, TruncatedHugeAndEndlessFilesAreRefusedWithTheReason) {
  const auto dir = test::scratch_dir("jpeg_bad");
  const auto rgb = smooth_rgb(64, 48);
  const std::string good = encode_jpeg(rgb, 64, 48, 3, JCS_RGB, false);
  // Cut in the middle of the scan: libjpeg would fill the rest with grey.
  write_bytes(dir / "cut.jpg", good.substr(0, good.size() / 2));
  EXPECT_NE(jpeg_error(dir / "cut.jpg")
                .find("cut.jpg: cannot decode JPEG: Premature end of JPEG "
                      "file"),
            std::string::npos)
      << jpeg_error(dir / "cut.jpg");
  // A frame header declaring 20000 x 20000 pixels: refused before anything is allocated.
  std::string huge = good;
  const std::size_t sof = huge.find("\xff\xc0");
  ASSERT_NE(sof, std::string::npos);
  for (const std::size_t at : {sof + 5, sof + 7}) {
    huge[at] = char(20000 >> 8);
    huge[at + 1] = char(20000 & 0xFF);
  }
  write_bytes(dir / "huge.jpg", huge);
  EXPECT_NE(jpeg_error(dir / "huge.jpg").find("JPEG image is 20000x20000 (400 M pixels)"),
            std::string::npos)
      << jpeg_error(dir / "huge.jpg");
  // A progressive file whose last scan repeats 1,100 times (libjpeg only warns about such a
  // progression and decodes every scan again).
  const std::string prog = encode_jpeg(rgb, 64, 48, 3, JCS_RGB, true);
  const std::size_t last_sos = prog.rfind("\xff\xda");
  const std::size_t eoi = prog.rfind("\xff\xd9");
  ASSERT_TRUE(last_sos != std::string::npos && eoi != std::string::npos && eoi > last_sos);
  std::string endless = prog.substr(0, eoi);
  for (int k = 0; k < 1100; ++k) endless += prog.substr(last_sos, eoi - last_sos);
  endless += "\xff\xd9";
  write_bytes(dir / "endless.jpg", endless);
  EXPECT_NE(jpeg_error(dir / "endless.jpg").find("more than 1000 scans"), std::string::npos)
      << jpeg_error(dir / "endless.jpg");
  // The same file with its own scans only still reads.
  write_bytes(dir / "prog.jpg", prog);
  EXPECT_EQ(read_png_rgba(dir / "prog.jpg").width(), 64);
  // Only the JPEG start of image, and a file that ends right after it.
  write_bytes(dir / "soi.jpg", std::string("\xff\xd8\xff", 3));
  EXPECT_NE(jpeg_error(dir / "soi.jpg").find("cannot decode JPEG"), std::string::npos)
      << jpeg_error(dir / "soi.jpg");
}
