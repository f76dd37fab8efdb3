#include <gtest/gtest.h>
#include <zlib.h>

#include <cstdint>
#include <opencv2/core.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "sonarbench/sim/report/images.hpp"

namespace sonarbench::sim {
namespace {

struct Decoded {
  std::uint32_t width = 0, height = 0;
  int colour_type = -1;
  std::vector<unsigned char> pixels;  // unfiltered rows, RGB(A) order
};

std::uint32_t U32(const std::vector<unsigned char>& b, std::size_t at) {
  return (std::uint32_t{b[at]} << 24) | (std::uint32_t{b[at + 1]} << 16) |
         (std::uint32_t{b[at + 2]} << 8) | b[at + 3];
}

// A reader of the PNG spec's chunks, CRCs and the five filters, independent of the encoder.
Decoded Decode(const std::vector<unsigned char>& png) {
  const std::vector<unsigned char> signature = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  if (png.size() < 8 || !std::equal(signature.begin(), signature.end(), png.begin())) {
    throw std::runtime_error("no PNG signature");
  }
  Decoded image;
  std::vector<unsigned char> idat;
  for (std::size_t at = 8; at + 12 <= png.size();) {
    const std::uint32_t size = U32(png, at);
    const std::string type(png.begin() + at + 4, png.begin() + at + 8);
    const uLong crc = crc32(0L, png.data() + at + 4, size + 4);
    if (crc != U32(png, at + 8 + size)) throw std::runtime_error("bad CRC in " + type);
    const unsigned char* data = png.data() + at + 8;
    if (type == "IHDR") {
      image.width = U32(png, at + 8);
      image.height = U32(png, at + 12);
      image.colour_type = data[9];
    }
    if (type == "IDAT") idat.insert(idat.end(), data, data + size);
    at += 12 + size;
  }
  const int channels = image.colour_type == 0 ? 1 : image.colour_type == 2 ? 3 : 4;
  const std::size_t row = image.width * channels;
  std::vector<unsigned char> raw((row + 1) * image.height);
  uLongf raw_size = raw.size();
  if (uncompress(raw.data(), &raw_size, idat.data(), idat.size()) != Z_OK || raw_size != raw.size())
    throw std::runtime_error("IDAT does not inflate to the image's rows");
  std::vector<unsigned char> previous(row, 0);
  for (std::size_t y = 0; y < image.height; ++y) {
    const unsigned char filter = raw[y * (row + 1)];
    std::vector<unsigned char> line(raw.begin() + y * (row + 1) + 1,
                                    raw.begin() + (y + 1) * (row + 1));
    for (std::size_t x = 0; x < row; ++x) {
      const int a = x >= static_cast<std::size_t>(channels) ? line[x - channels] : 0;
      const int b = previous[x];
      const int c = x >= static_cast<std::size_t>(channels) ? previous[x - channels] : 0;
      const int p = a + b - c;
      const int paeth = (std::abs(p - a) <= std::abs(p - b) && std::abs(p - a) <= std::abs(p - c))
                            ? a
                            : (std::abs(p - b) <= std::abs(p - c) ? b : c);
      const int predictor = filter == 0   ? 0
                            : filter == 1 ? a
                            : filter == 2 ? b
                            : filter == 3 ? (a + b) / 2
                                          : paeth;
      line[x] = static_cast<unsigned char>(line[x] + predictor);
    }
    image.pixels.insert(image.pixels.end(), line.begin(), line.end());
    previous = line;
  }
  return image;
}

cv::Mat Pattern(int rows, int cols, int type) {
  cv::Mat image(rows, cols, type);
  cv::randu(image, 0, 256);
  image.rowRange(0, rows / 2).setTo(cv::Scalar::all(7));  // flat rows, as figures have
  return image;
}

TEST(EncodePng, GrayImagesDecodeToTheirPixels) {
  const cv::Mat image = Pattern(37, 53, CV_8UC1);
  const Decoded png = Decode(EncodePng(image));
  EXPECT_EQ(png.width, 53u);
  EXPECT_EQ(png.height, 37u);
  EXPECT_EQ(png.colour_type, 0);
  ASSERT_EQ(png.pixels.size(), image.total());
  EXPECT_TRUE(std::equal(png.pixels.begin(), png.pixels.end(), image.ptr<unsigned char>(0)));
}

TEST(EncodePng, ColourImagesAreWrittenRgbFromOpenCvsBgr) {
  for (const int type : {CV_8UC3, CV_8UC4}) {
    const cv::Mat image = Pattern(19, 41, type);
    const int channels = image.channels();
    const Decoded png = Decode(EncodePng(image));
    EXPECT_EQ(png.colour_type, channels == 3 ? 2 : 6);
    ASSERT_EQ(png.pixels.size(), image.total() * channels);
    for (int y = 0; y < image.rows; ++y) {
      for (int x = 0; x < image.cols; ++x) {
        const unsigned char* bgr = image.ptr<unsigned char>(y) + x * channels;
        const unsigned char* rgb = png.pixels.data() + (y * image.cols + x) * channels;
        ASSERT_EQ(rgb[0], bgr[2]);
        ASSERT_EQ(rgb[1], bgr[1]);
        ASSERT_EQ(rgb[2], bgr[0]);
        if (channels == 4) {
          ASSERT_EQ(rgb[3], bgr[3]);
        }
      }
    }
  }
}

TEST(EncodePng, ImagesItCannotWriteAreRefused) {
  EXPECT_THROW((void)EncodePng(cv::Mat()), std::runtime_error);
  EXPECT_THROW((void)EncodePng(cv::Mat(4, 4, CV_16UC1, cv::Scalar(1))), std::runtime_error);
  EXPECT_THROW((void)EncodePng(cv::Mat(4, 4, CV_8UC2, cv::Scalar(1))), std::runtime_error);
}

}  // namespace
}  // namespace sonarbench::sim
