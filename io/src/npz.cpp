#include "sonarbench/io/npz.hpp"

#include <zlib.h>

#include <algorithm>
#include <fstream>
#include <iterator>
#include <stdexcept>

#include "sonarbench/base/error.hpp"

namespace sonarbench::io {
namespace {

constexpr std::uint64_t kZipLimit = 0xFFFFFFFFULL;
// 1980-01-01 00:00, the earliest a zip can say: the same arrays give the same bytes.
constexpr std::uint16_t kDosDate = (0 << 9) | (1 << 5) | 1;

template <typename T>
void Put(std::string& out, T value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof value);
}

std::size_t TypeSize(const std::string& descr) {
  if (descr.size() < 3) throw std::invalid_argument("npz: type '" + descr + "'");
  const std::size_t n = std::stoul(descr.substr(2));
  return descr[1] == 'U' ? 4 * n : n;
}

// The .npy header: magic, version 1.0, its length and the dictionary, padded to 64 bytes.
std::string NpyHeader(const std::string& descr, const std::vector<std::size_t>& shape) {
  std::string dims;
  for (const std::size_t d : shape) dims += (dims.empty() ? "" : ", ") + std::to_string(d);
  if (shape.size() == 1) dims += ",";
  std::string dict =
      "{'descr': '" + descr + "', 'fortran_order': False, 'shape': (" + dims + "), }";
  const std::size_t unpadded = 10 + dict.size() + 1;
  dict.append((64 - unpadded % 64) % 64, ' ');
  dict += '\n';
  std::string header = "\x93NUMPY";
  header += '\x01';
  header += '\x00';
  Put<std::uint16_t>(header, static_cast<std::uint16_t>(dict.size()));
  return header + dict;
}

std::string Deflate(std::string_view head, std::string_view data, std::uint32_t& crc) {
  z_stream z{};
  if (deflateInit2(&z, 6, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) != Z_OK) {
    throw std::runtime_error("zlib: deflateInit2 failed");
  }
  std::string out(deflateBound(&z, head.size() + data.size()), '\0');
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = static_cast<uInt>(out.size());
  crc = static_cast<std::uint32_t>(crc32(0L, Z_NULL, 0));
  for (const std::string_view part : {head, data}) {
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(part.data()));
    z.avail_in = static_cast<uInt>(part.size());
    if (deflate(&z, Z_NO_FLUSH) != Z_OK) throw std::runtime_error("zlib: deflate failed");
    crc = static_cast<std::uint32_t>(
        crc32(crc, reinterpret_cast<const Bytef*>(part.data()), static_cast<uInt>(part.size())));
  }
  if (deflate(&z, Z_FINISH) != Z_STREAM_END) throw std::runtime_error("zlib: deflate failed");
  out.resize(z.total_out);
  deflateEnd(&z);
  return out;
}

// A zip header's fields from "version needed" to the extra field's length.
void PutEntryFields(std::string& out, const std::string& name, std::uint32_t crc,
                    std::uint64_t deflated, std::uint64_t size) {
  Put<std::uint16_t>(out, 20);  // version needed: deflate
  Put<std::uint16_t>(out, 0);   // flags
  Put<std::uint16_t>(out, 8);   // deflate
  Put<std::uint16_t>(out, 0);   // time
  Put<std::uint16_t>(out, kDosDate);
  Put<std::uint32_t>(out, crc);
  Put<std::uint32_t>(out, static_cast<std::uint32_t>(deflated));
  Put<std::uint32_t>(out, static_cast<std::uint32_t>(size));
  Put<std::uint16_t>(out, static_cast<std::uint16_t>(name.size()));
  Put<std::uint16_t>(out, 0);  // extra field
}

}  // namespace

void NpzArchive::Add(const std::string& name, const std::string& descr,
                     const std::vector<std::size_t>& shape, std::string_view data) {
  std::size_t count = 1;
  for (const std::size_t d : shape) count *= d;
  if (count * TypeSize(descr) != data.size()) {
    throw std::invalid_argument("npz: array '" + name + "' holds " + std::to_string(data.size()) +
                                " bytes, not its shape's");
  }
  const std::string header = NpyHeader(descr, shape);
  if (header.size() + data.size() > kZipLimit) {
    throw InputError("npz: array '" + name + "' would take " +
                     std::to_string(header.size() + data.size()) +
                     " bytes; an .npz file holds at most 4 GiB an array: export fewer sweeps");
  }
  Entry entry;
  entry.name = name + ".npy";
  entry.size = header.size() + data.size();
  entry.deflated = Deflate(header, data, entry.crc);
  entries_.push_back(std::move(entry));
}

void NpzArchive::Write(std::ostream& out, const std::string& comment) const {
  std::string zip;
  std::string directory;
  for (const Entry& e : entries_) {
    if (zip.size() > kZipLimit) throw InputError("npz: the archive passes 4 GiB");
    Put<std::uint32_t>(directory, 0x02014b50);
    Put<std::uint16_t>(directory, 20);  // made by
    PutEntryFields(directory, e.name, e.crc, e.deflated.size(), e.size);
    Put<std::uint16_t>(directory, 0);  // comment
    Put<std::uint16_t>(directory, 0);  // disk
    Put<std::uint16_t>(directory, 0);  // internal attributes
    Put<std::uint32_t>(directory, 0);  // external attributes
    Put<std::uint32_t>(directory, static_cast<std::uint32_t>(zip.size()));
    directory += e.name;
    Put<std::uint32_t>(zip, 0x04034b50);
    PutEntryFields(zip, e.name, e.crc, e.deflated.size(), e.size);
    zip += e.name;
    zip += e.deflated;
  }
  if (zip.size() > kZipLimit) throw InputError("npz: the archive passes 4 GiB");
  const auto entries = static_cast<std::uint16_t>(entries_.size());
  const auto at = static_cast<std::uint32_t>(zip.size());
  zip += directory;
  Put<std::uint32_t>(zip, 0x06054b50);
  Put<std::uint16_t>(zip, 0);
  Put<std::uint16_t>(zip, 0);
  Put<std::uint16_t>(zip, entries);
  Put<std::uint16_t>(zip, entries);
  Put<std::uint32_t>(zip, static_cast<std::uint32_t>(directory.size()));
  Put<std::uint32_t>(zip, at);
  Put<std::uint16_t>(zip, static_cast<std::uint16_t>(comment.size()));
  zip += comment;
  out.write(zip.data(), static_cast<std::streamsize>(zip.size()));
}

std::optional<std::string> NpzComment(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return std::nullopt;
  in.seekg(0, std::ios::end);
  const auto size = static_cast<std::size_t>(in.tellg());
  const std::size_t tail = std::min<std::size_t>(size, 22 + 0xFFFF);
  std::string bytes(tail, '\0');
  in.seekg(static_cast<std::streamoff>(size - tail));
  in.read(bytes.data(), static_cast<std::streamsize>(tail));
  // The end record (22 bytes, its comment after it), searched for from the end.
  for (std::size_t at = tail < 22 ? 0 : tail - 21; at-- > 0;) {
    if (bytes.compare(at, 4, "PK\x05\x06") != 0) continue;
    const std::size_t length = static_cast<unsigned char>(bytes[at + 20]) |
                               (static_cast<unsigned char>(bytes[at + 21]) << 8);
    if (at + 22 + length == tail) return bytes.substr(at + 22, length);
  }
  return std::nullopt;
}

std::pair<std::string, std::size_t> NumpyUnicode(const std::vector<std::string>& strings) {
  std::size_t width = 1;
  for (const std::string& s : strings) width = std::max(width, s.size());
  std::string bytes;
  for (const std::string& s : strings) {
    for (std::size_t i = 0; i < width; ++i) {
      Put<std::uint32_t>(bytes, i < s.size() ? static_cast<unsigned char>(s[i]) : 0U);
    }
  }
  return {bytes, width};
}

}  // namespace sonarbench::io
