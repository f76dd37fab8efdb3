#include "sonarbench/io/mcap.hpp"

#include <zlib.h>
#include <zstd.h>

#include <array>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <string_view>

#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/io/text.hpp"

namespace sonarbench::io {
namespace {

constexpr std::size_t kMagicSize = 8;
constexpr std::uint64_t kChunkBytes = 1 << 20;  // a chunk closes past this many record bytes

enum Op : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kStatistics = 0x0B,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

std::uint32_t Crc32(std::string_view bytes) {
  uLong crc = crc32(0L, Z_NULL, 0);
  // zlib takes lengths as uInt; feed large inputs in pieces.
  for (std::size_t at = 0; at < bytes.size(); at += 1u << 30) {
    const std::size_t n = std::min<std::size_t>(bytes.size() - at, 1u << 30);
    crc = crc32(crc, reinterpret_cast<const Bytef*>(bytes.data() + at), static_cast<uInt>(n));
  }
  return static_cast<std::uint32_t>(crc);
}

// Little-endian appends, as every MCAP field is.
template <typename T>
void Put(std::string& out, T value) {
  for (std::size_t i = 0; i < sizeof(T); ++i) {
    out += static_cast<char>((static_cast<std::uint64_t>(value) >> (8 * i)) & 0xFF);
  }
}
void PutString(std::string& out, std::string_view s) {
  Put<std::uint32_t>(out, static_cast<std::uint32_t>(s.size()));
  out += s;
}
std::string Record(std::uint8_t opcode, const std::string& body) {
  std::string r(1, static_cast<char>(opcode));
  Put<std::uint64_t>(r, body.size());
  return r + body;
}

std::string SchemaBody(const McapSchema& s) {
  std::string b;
  Put<std::uint16_t>(b, s.id);
  PutString(b, s.name);
  PutString(b, s.encoding);
  PutString(b, s.data);
  return b;
}
std::string ChannelBody(const McapChannel& c) {
  std::string b;
  Put<std::uint16_t>(b, c.id);
  Put<std::uint16_t>(b, c.schema_id);
  PutString(b, c.topic);
  PutString(b, c.message_encoding);
  std::string map;
  for (const auto& [key, value] : c.metadata) {
    PutString(map, key);
    PutString(map, value);
  }
  PutString(b, map);
  return b;
}

// Reads little-endian fields from one record's bytes; a short read names the record.
class Cursor {
 public:
  Cursor(std::string_view bytes, std::string where) : bytes_(bytes), where_(std::move(where)) {}
  template <typename T>
  T Get(const char* field) {
    Need(sizeof(T), field);
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i) {
      v |= static_cast<std::uint64_t>(static_cast<unsigned char>(bytes_[at_ + i])) << (8 * i);
    }
    at_ += sizeof(T);
    return static_cast<T>(v);
  }
  std::string_view Bytes(std::uint64_t n, const char* field) {
    Need(n, field);
    const std::string_view v = bytes_.substr(at_, n);
    at_ += n;
    return v;
  }
  std::string String(const char* field) {
    return std::string(Bytes(Get<std::uint32_t>(field), field));
  }
  std::string_view Rest() { return Bytes(bytes_.size() - at_, "data"); }
  [[nodiscard]] bool Done() const { return at_ == bytes_.size(); }
  [[noreturn]] void Fail(const std::string& what) const { throw InputError(where_ + what); }

 private:
  void Need(std::uint64_t n, const char* field) const {
    if (n > bytes_.size() - at_) {
      Fail(std::string("field '") + field + "' runs past the record's end");
    }
  }
  std::string_view bytes_;
  std::size_t at_ = 0;
  std::string where_;
};

class Reader {
 public:
  Reader(std::string path, std::uint64_t max_bytes) : path_(std::move(path)), budget_(max_bytes) {}
  McapFile Read();

 private:
  [[noreturn]] void Fail(std::uint64_t offset, const std::string& what) const {
    throw InputError(path_ + ": byte " + std::to_string(offset) + ": " + what);
  }
  // Walks the records of `bytes` (the file's or a chunk's), `base` the offset named in messages.
  // Returns the offset just past the footer (file level), or bytes.size().
  std::size_t Records(std::string_view bytes, std::size_t from, std::uint64_t base, bool chunk);
  void OnRecord(std::uint8_t op, std::string_view body, std::uint64_t offset, bool chunk);
  void OnChunk(Cursor& c, std::uint64_t offset);
  void OnFooter(Cursor& c, std::uint64_t offset);

  std::string path_;
  std::uint64_t budget_;
  std::string file_;
  McapFile result_;
  std::set<std::uint16_t> schema_ids_, channel_ids_;
  bool header_ = false, footer_ = false;
};

McapFile Reader::Read() {
  const std::uint64_t size = CheckInputFile(path_, std::numeric_limits<std::uint64_t>::max());
  if (size > budget_) {
    Fail(0, "the file holds " + ByteCount(size) + ", more than the " + ByteCount(budget_) +
                " sonarbench reads from one log (import's --max-input-mb raises it)");
  }
  file_ = ReadFileBytes(path_, budget_);
  budget_ -= file_.size();
  if (file_.size() < 2 * kMagicSize || file_.compare(0, kMagicSize, kMcapMagic) != 0) {
    Fail(0, "not an MCAP file: expected the magic bytes 0x89 'MCAP0' '\\r\\n' at its start");
  }
  const std::size_t end = Records(file_, kMagicSize, 0, false);
  if (!header_) Fail(kMagicSize, "expected a header record first");
  if (!footer_) Fail(file_.size(), "the file ends without a footer record (truncated?)");
  if (file_.size() - end != kMagicSize || file_.compare(end, kMagicSize, kMcapMagic) != 0) {
    Fail(end, "expected the closing magic bytes right after the footer, then the end");
  }
  return std::move(result_);
}

std::size_t Reader::Records(std::string_view bytes, std::size_t at, std::uint64_t base,
                            bool chunk) {
  while (at < bytes.size() && !footer_) {
    const std::uint64_t offset = base + at;
    if (bytes.size() - at < 9) Fail(offset, "a record header is cut off (truncated file?)");
    Cursor head(bytes.substr(at, 9), "");
    const auto op = head.Get<std::uint8_t>("opcode");
    const auto length = head.Get<std::uint64_t>("length");
    if (length > bytes.size() - at - 9) {
      Fail(offset, "record of opcode " + std::to_string(op) + " declares " +
                       std::to_string(length) + " bytes; only " +
                       std::to_string(bytes.size() - at - 9) + " follow (truncated file?)");
    }
    if (!chunk && !header_ && op != kHeader) Fail(offset, "expected a header record first");
    OnRecord(op, bytes.substr(at + 9, length), offset, chunk);
    at += 9 + length;
  }
  return at;
}

void Reader::OnRecord(std::uint8_t op, std::string_view body, std::uint64_t offset, bool chunk) {
  Cursor c(body, path_ + ": byte " + std::to_string(offset) + ": ");
  if (chunk && op != kSchema && op != kChannel && op != kMessage) {
    Fail(offset, "a chunk may hold schema, channel and message records only; found opcode " +
                     std::to_string(op));
  }
  if (op == kHeader) {
    if (header_) Fail(offset, "a second header record");
    header_ = true;
    result_.profile = c.String("profile");
    result_.library = c.String("library");
  } else if (op == kSchema) {
    McapSchema s{c.Get<std::uint16_t>("id"), c.String("name"), c.String("encoding"),
                 c.String("data")};
    if (s.id == 0) Fail(offset, "schema id 0 is reserved");
    if (schema_ids_.insert(s.id).second) result_.schemas.push_back(std::move(s));
  } else if (op == kChannel) {
    McapChannel ch{c.Get<std::uint16_t>("id"),
                   c.Get<std::uint16_t>("schema_id"),
                   c.String("topic"),
                   c.String("message_encoding"),
                   {}};
    Cursor map(c.Bytes(c.Get<std::uint32_t>("metadata"), "metadata"), "");
    while (!map.Done()) ch.metadata[map.String("metadata")] = map.String("metadata");
    if (!IsUtf8(ch.topic)) Fail(offset, "channel topic " + Quoted(ch.topic) + " is not UTF-8");
    if (ch.schema_id != 0 && !schema_ids_.count(ch.schema_id)) {
      Fail(offset, "channel " + std::to_string(ch.id) + " names schema " +
                       std::to_string(ch.schema_id) + ", which no schema record before it defines");
    }
    if (channel_ids_.insert(ch.id).second) result_.channels.push_back(std::move(ch));
  } else if (op == kMessage) {
    McapMessage m{c.Get<std::uint16_t>("channel_id"),
                  c.Get<std::uint32_t>("sequence"),
                  c.Get<std::uint64_t>("log_time"),
                  c.Get<std::uint64_t>("publish_time"),
                  {}};
    if (!channel_ids_.count(m.channel_id)) {
      Fail(offset, "a message on channel " + std::to_string(m.channel_id) +
                       ", which no channel record before it defines");
    }
    m.data = std::string(c.Rest());
    result_.messages.push_back(std::move(m));
  } else if (op == kChunk) {
    OnChunk(c, offset);
  } else if (op == kStatistics) {
    result_.has_summary = true;
  } else if (op == kFooter) {
    OnFooter(c, offset);
  }
  // Other records (indexes, attachments, metadata, data end) carry nothing a reader of beams
  // needs; unknown opcodes are skipped, as the specification asks.
}

void Reader::OnChunk(Cursor& c, std::uint64_t offset) {
  c.Get<std::uint64_t>("message_start_time");
  c.Get<std::uint64_t>("message_end_time");
  const auto size = c.Get<std::uint64_t>("uncompressed_size");
  const auto crc = c.Get<std::uint32_t>("uncompressed_crc");
  const std::string compression = c.String("compression");
  const std::string_view stored = c.Bytes(c.Get<std::uint64_t>("records"), "records");
  std::string plain;
  if (compression.empty()) {
    if (size != stored.size()) Fail(offset, "chunk's uncompressed_size differs from its records");
    plain = stored;
  } else if (compression == "zstd") {
    if (size > budget_) {
      Fail(offset, "chunk of " + ByteCount(size) + " uncompressed: more than the " +
                       ByteCount(budget_) + " left of what sonarbench reads from one log " +
                       "(import's --max-input-mb raises it)");
    }
    plain.resize(size);
    const std::size_t n = ZSTD_decompress(plain.data(), plain.size(), stored.data(), stored.size());
    if (ZSTD_isError(n) || n != size) {
      Fail(offset, std::string("zstd chunk does not decompress to its uncompressed_size (") +
                       (ZSTD_isError(n) ? ZSTD_getErrorName(n) : "size differs") + ")");
    }
    budget_ -= size;
  } else {
    Fail(offset, "chunk compression " + Quoted(compression) +
                     " is not read; expected none or zstd (`mcap convert` or `ros2 bag convert` "
                     "rewrite a bag)");
  }
  if (crc != 0 && Crc32(plain) != crc) Fail(offset, "chunk's CRC-32 does not match its records");
  Records(plain, 0, offset, true);
}

void Reader::OnFooter(Cursor& c, std::uint64_t offset) {
  const auto summary_start = c.Get<std::uint64_t>("summary_start");
  c.Get<std::uint64_t>("summary_offset_start");
  const auto crc = c.Get<std::uint32_t>("summary_crc");
  footer_ = true;
  if (summary_start > offset) Fail(offset, "footer's summary_start lies past the footer");
  // The CRC covers the summary through the footer's summary_offset_start field.
  const std::uint64_t crc_end = offset + 1 + 8 + 8 + 8;
  if (crc != 0 && summary_start != 0 &&
      Crc32(std::string_view(file_).substr(summary_start, crc_end - summary_start)) != crc) {
    Fail(offset, "the summary's CRC-32 does not match");
  }
}

}  // namespace

McapWriter::McapWriter(std::ostream& out, const std::string& profile, const std::string& library)
    : out_(out) {
  out_.write(kMcapMagic, kMagicSize);
  offset_ = kMagicSize;
  std::string header;
  PutString(header, profile);
  PutString(header, library);
  Emit(kHeader, header);
}

void McapWriter::Emit(std::uint8_t opcode, const std::string& body) {
  const std::string r = Record(opcode, body);
  out_.write(r.data(), static_cast<std::streamsize>(r.size()));
  offset_ += r.size();
}

void McapWriter::Add(const McapSchema& schema) {
  schemas_.push_back(schema);
  Emit(kSchema, SchemaBody(schema));
}

void McapWriter::Add(const McapChannel& channel) {
  channels_.push_back(channel);
  channel_counts_[channel.id] = 0;
  Emit(kChannel, ChannelBody(channel));
}

void McapWriter::Write(const McapMessage& m) {
  if (chunk_.empty()) chunk_start_ns_ = m.log_time_ns;
  chunk_end_ns_ = m.log_time_ns;
  chunk_index_[m.channel_id].emplace_back(m.log_time_ns, chunk_.size());
  std::string body;
  Put<std::uint16_t>(body, m.channel_id);
  Put<std::uint32_t>(body, m.sequence);
  Put<std::uint64_t>(body, m.log_time_ns);
  Put<std::uint64_t>(body, m.publish_time_ns);
  chunk_ += Record(kMessage, body + m.data);
  if (messages_++ == 0) first_ns_ = m.log_time_ns;
  last_ns_ = m.log_time_ns;
  ++channel_counts_[m.channel_id];
  if (chunk_.size() >= kChunkBytes) FlushChunk();
}

void McapWriter::FlushChunk() {
  if (chunk_.empty()) return;
  ChunkIndex index{chunk_start_ns_, chunk_end_ns_, offset_, 0, 0, chunk_.size(), {}};
  std::string body;
  Put<std::uint64_t>(body, chunk_start_ns_);
  Put<std::uint64_t>(body, chunk_end_ns_);
  Put<std::uint64_t>(body, chunk_.size());
  Put<std::uint32_t>(body, Crc32(chunk_));
  PutString(body, "");
  Put<std::uint64_t>(body, chunk_.size());
  Emit(kChunk, body + chunk_);
  index.length = offset_ - index.offset;
  const std::uint64_t indexes_start = offset_;
  for (const auto& [channel, entries] : chunk_index_) {
    std::string b;
    Put<std::uint16_t>(b, channel);
    Put<std::uint32_t>(b, static_cast<std::uint32_t>(entries.size() * 16));
    for (const auto& [time, at] : entries) {
      Put<std::uint64_t>(b, time);
      Put<std::uint64_t>(b, at);
    }
    index.index_offsets[channel] = offset_;
    Emit(kMessageIndex, b);
  }
  index.index_length = offset_ - indexes_start;
  chunks_.push_back(index);
  chunk_.clear();
  chunk_index_.clear();
}

std::string McapWriter::StatisticsBody() const {
  std::string stats;
  Put<std::uint64_t>(stats, messages_);
  Put<std::uint16_t>(stats, static_cast<std::uint16_t>(schemas_.size()));
  Put<std::uint32_t>(stats, static_cast<std::uint32_t>(channels_.size()));
  Put<std::uint32_t>(stats, 0);  // attachments
  Put<std::uint32_t>(stats, 0);  // metadata
  Put<std::uint32_t>(stats, static_cast<std::uint32_t>(chunks_.size()));
  Put<std::uint64_t>(stats, first_ns_);
  Put<std::uint64_t>(stats, last_ns_);
  std::string counts;
  for (const auto& [channel, n] : channel_counts_) {
    Put<std::uint16_t>(counts, channel);
    Put<std::uint64_t>(counts, n);
  }
  PutString(stats, counts);
  return stats;
}

std::string McapWriter::ChunkIndexBody(const ChunkIndex& c) {
  std::string b;
  Put<std::uint64_t>(b, c.start_ns);
  Put<std::uint64_t>(b, c.end_ns);
  Put<std::uint64_t>(b, c.offset);
  Put<std::uint64_t>(b, c.length);
  std::string offsets;
  for (const auto& [channel, at] : c.index_offsets) {
    Put<std::uint16_t>(offsets, channel);
    Put<std::uint64_t>(offsets, at);
  }
  PutString(b, offsets);
  Put<std::uint64_t>(b, c.index_length);
  PutString(b, "");
  Put<std::uint64_t>(b, c.records_size);
  Put<std::uint64_t>(b, c.records_size);
  return b;
}

void McapWriter::Finish() {
  if (finished_) return;
  finished_ = true;
  FlushChunk();
  Emit(kDataEnd, std::string(4, '\0'));  // data section CRC: not computed (0)
  const std::uint64_t summary_start = offset_;
  std::string summary;                               // kept for the footer's CRC
  std::vector<std::array<std::uint64_t, 3>> groups;  // opcode, start, length
  const auto group = [&](std::uint8_t op, const std::vector<std::string>& bodies) {
    const std::uint64_t start = offset_;
    for (const std::string& b : bodies) {
      summary += Record(op, b);
      Emit(op, b);
    }
    if (!bodies.empty()) groups.push_back({op, start, offset_ - start});
  };
  std::vector<std::string> bodies;
  for (const McapSchema& s : schemas_) bodies.push_back(SchemaBody(s));
  group(kSchema, bodies);
  bodies.clear();
  for (const McapChannel& c : channels_) bodies.push_back(ChannelBody(c));
  group(kChannel, bodies);
  group(kStatistics, {StatisticsBody()});
  bodies.clear();
  for (const ChunkIndex& c : chunks_) bodies.push_back(ChunkIndexBody(c));
  group(kChunkIndex, bodies);
  const std::uint64_t offsets_start = offset_;
  for (const auto& [op, start, length] : groups) {
    std::string b;
    Put<std::uint8_t>(b, static_cast<std::uint8_t>(op));
    Put<std::uint64_t>(b, start);
    Put<std::uint64_t>(b, length);
    summary += Record(kSummaryOffset, b);
    Emit(kSummaryOffset, b);
  }
  std::string footer;
  Put<std::uint64_t>(footer, summary_start);
  Put<std::uint64_t>(footer, offsets_start);
  summary += Record(kFooter, footer + std::string(4, '\0')).substr(0, 1 + 8 + footer.size());
  Put<std::uint32_t>(footer, Crc32(summary));
  Emit(kFooter, footer);
  out_.write(kMcapMagic, kMagicSize);
}

bool StartsAsMcap(const std::string& path) {
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) return false;  // never waits on a FIFO
  std::string magic(kMagicSize, '\0');
  std::ifstream in(path, std::ios::binary);
  return in.read(magic.data(), kMagicSize) && magic == std::string(kMcapMagic, kMagicSize);
}

std::optional<std::string> McapLibrary(const std::string& path) {
  constexpr std::uint64_t kMaxHeader = 1 << 20;  // a header's two strings; longer is not MCAP
  std::error_code error;
  if (!std::filesystem::is_regular_file(path, error)) return std::nullopt;
  std::ifstream in(path, std::ios::binary);
  std::string head(kMagicSize + 9, '\0');
  if (!in.read(head.data(), static_cast<std::streamsize>(head.size())) ||
      head.compare(0, kMagicSize, kMcapMagic) != 0 || head[kMagicSize] != kHeader) {
    return std::nullopt;
  }
  const auto length =
      Cursor(std::string_view(head).substr(kMagicSize + 1), "").Get<std::uint64_t>("length");
  if (length > kMaxHeader) return std::nullopt;
  std::string body(length, '\0');
  if (!in.read(body.data(), static_cast<std::streamsize>(length))) return std::nullopt;
  try {
    Cursor c(body, "");
    (void)c.String("profile");
    return c.String("library");
  } catch (const InputError&) {
    return std::nullopt;
  }
}

McapFile ReadMcap(const std::string& path, std::uint64_t max_bytes) {
  return Reader(path, max_bytes).Read();
}

}  // namespace sonarbench::io
