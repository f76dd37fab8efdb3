#include <zlib.h>

#include <array>
#include <cstdint>
#include <stdexcept>

#include "sonarbench/sim/report/images.hpp"

namespace sonarbench::sim {
namespace {

void PutU32(std::vector<unsigned char>& out, std::uint32_t value) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back((value >> shift) & 0xff);
}

// A chunk: length, type, data, and the CRC-32 of type and data (PNG spec, section 5.3).
void PutChunk(std::vector<unsigned char>& out, const char (&type)[5], const unsigned char* data,
              std::size_t size) {
  if (size > 0x7fffffffu) throw std::runtime_error("PNG encoding failed: a chunk over 2^31 bytes");
  PutU32(out, static_cast<std::uint32_t>(size));
  const std::size_t start = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), data, data + size);
  const uLong crc = crc32(0L, out.data() + start, static_cast<uInt>(size + 4));
  PutU32(out, static_cast<std::uint32_t>(crc));
}

// The image's rows as PNG scanlines (RGB(A) order), each filtered with "Sub": its first byte 1,
// then each byte minus the byte of the pixel to its left.
std::vector<unsigned char> SubFilteredRows(const cv::Mat& image, int channels) {
  const std::size_t row_bytes = static_cast<std::size_t>(image.cols) * channels;
  std::vector<unsigned char> rows((row_bytes + 1) * static_cast<std::size_t>(image.rows));
  std::vector<unsigned char> pixels(row_bytes);
  for (int y = 0; y < image.rows; ++y) {
    const unsigned char* in = image.ptr<unsigned char>(y);
    for (std::size_t x = 0; x < row_bytes; x += channels) {  // BGR(A) to RGB(A)
      for (int c = 0; c < channels; ++c) {
        pixels[x + c] = in[x + (c < 3 && channels >= 3 ? 2 - c : c)];
      }
    }
    unsigned char* out = rows.data() + static_cast<std::size_t>(y) * (row_bytes + 1);
    out[0] = 1;
    for (std::size_t x = 0; x < row_bytes; ++x) {
      out[1 + x] = static_cast<unsigned char>(
          pixels[x] - (x >= static_cast<std::size_t>(channels) ? pixels[x - channels] : 0));
    }
  }
  return rows;
}

}  // namespace

std::vector<unsigned char> EncodePng(const cv::Mat& image) {
  const int depth = image.depth();
  const int channels = image.channels();
  if (depth != CV_8U || (channels != 1 && channels != 3 && channels != 4) || image.empty()) {
    throw std::runtime_error("PNG encoding failed: expected an 8-bit image of 1, 3 or 4 channels");
  }
  const std::vector<unsigned char> rows = SubFilteredRows(image, channels);
  if (rows.size() > 0xffffffffu) throw std::runtime_error("PNG encoding failed: over 4 GB of rows");
  z_stream stream{};
  // Fastest deflate with run-length matching: images of flat colours compress well and quickly.
  if (deflateInit2(&stream, Z_BEST_SPEED, Z_DEFLATED, 15, 8, Z_RLE) != Z_OK) {
    throw std::runtime_error("PNG encoding failed: zlib cannot start");
  }
  std::vector<unsigned char> compressed(deflateBound(&stream, static_cast<uLong>(rows.size())));
  stream.next_in = const_cast<Bytef*>(rows.data());
  stream.avail_in = static_cast<uInt>(rows.size());
  stream.next_out = compressed.data();
  stream.avail_out = static_cast<uInt>(compressed.size());
  const int status = deflate(&stream, Z_FINISH);
  compressed.resize(stream.total_out);
  deflateEnd(&stream);
  if (status != Z_STREAM_END) throw std::runtime_error("PNG encoding failed: deflate");

  std::vector<unsigned char> png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  std::vector<unsigned char> header;
  PutU32(header, static_cast<std::uint32_t>(image.cols));
  PutU32(header, static_cast<std::uint32_t>(image.rows));
  const unsigned char colour_type = channels == 1 ? 0 : channels == 3 ? 2 : 6;
  header.insert(header.end(), {8, colour_type, 0, 0, 0});  // 8 bits, deflate, filters, no interlace
  PutChunk(png, "IHDR", header.data(), header.size());
  PutChunk(png, "IDAT", compressed.data(), compressed.size());
  PutChunk(png, "IEND", nullptr, 0);
  return png;
}

}  // namespace sonarbench::sim
