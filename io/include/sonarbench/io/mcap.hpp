#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace sonarbench::io {

/// MCAP (https://mcap.dev/spec), the container rosbag2 stores bags in: the records a ROS 2 bag
/// needs, written and read without a third-party library.
struct McapSchema {
  std::uint16_t id = 0;
  std::string name;      // "marine_acoustic_msgs/msg/ProjectedSonarImage"
  std::string encoding;  // "ros2msg"
  std::string data;      // the message definition
};

struct McapChannel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;
  std::string topic;
  std::string message_encoding;  // "cdr"
  std::map<std::string, std::string> metadata;
};

struct McapMessage {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time_ns = 0;
  std::uint64_t publish_time_ns = 0;
  std::string data;
};

/// Writes an indexed MCAP file: magic, header, schemas and channels, messages in uncompressed
/// chunks (each with its CRC-32 and a message index per channel), then a summary section
/// (schemas, channels, statistics, chunk indexes), summary offsets, the footer with the summary's
/// CRC-32, and the closing magic. Messages must come in log-time order.
class McapWriter {
 public:
  McapWriter(std::ostream& out, const std::string& profile, const std::string& library);
  void Add(const McapSchema& schema);
  void Add(const McapChannel& channel);
  void Write(const McapMessage& message);
  /// Writes the last chunk, the summary and the footer; the writer takes nothing after it.
  void Finish();

 private:
  void FlushChunk();
  void Emit(std::uint8_t opcode, const std::string& body);
  struct ChunkIndex {
    std::uint64_t start_ns, end_ns, offset, length, index_length, records_size;
    std::map<std::uint16_t, std::uint64_t> index_offsets;
  };
  [[nodiscard]] std::string StatisticsBody() const;
  [[nodiscard]] static std::string ChunkIndexBody(const ChunkIndex& c);

  std::ostream& out_;
  std::uint64_t offset_ = 0;
  std::vector<McapSchema> schemas_;
  std::vector<McapChannel> channels_;
  std::string chunk_;  // message records of the open chunk
  std::uint64_t chunk_start_ns_ = 0, chunk_end_ns_ = 0;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_index_;
  std::vector<ChunkIndex> chunks_;
  std::map<std::uint16_t, std::uint64_t> channel_counts_;
  std::uint64_t messages_ = 0, first_ns_ = 0, last_ns_ = 0;
  bool finished_ = false;
};

/// An MCAP file read whole: its header, schemas, channels and every message in file order.
struct McapFile {
  std::string profile;
  std::string library;
  std::vector<McapSchema> schemas;
  std::vector<McapChannel> channels;
  std::vector<McapMessage> messages;
  /// Messages found in the summary's statistics record (absent: no summary), to check against.
  bool has_summary = false;
};

/// Reads an MCAP file: magic at both ends, every record's length within its section, chunks
/// uncompressed or zstd with their CRC-32 checked, messages on declared channels, the summary's
/// CRC-32, and at most `max_bytes` of records after decompression (checked before allocating).
/// Throws InputError naming the file, the record's offset and what was expected.
[[nodiscard]] McapFile ReadMcap(const std::string& path, std::uint64_t max_bytes);

/// The first bytes of an MCAP file.
inline constexpr char kMcapMagic[] = "\x89MCAP0\r\n";

/// Whether `path` begins with kMcapMagic (a file that cannot be read does not).
[[nodiscard]] bool StartsAsMcap(const std::string& path);
/// The `library` field of the header record of the MCAP file `path` (who wrote it), or nullopt
/// when `path` does not begin as an MCAP file does. Reads the magic and the header only.
[[nodiscard]] std::optional<std::string> McapLibrary(const std::string& path);

}  // namespace sonarbench::io
