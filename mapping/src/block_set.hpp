#pragma once

#include <octomap/OcTreeKey.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "key_set.hpp"

namespace sonarbench::mapping {

/// Blocks found by their `origin` member (any 64-bit value) in an open-addressing table, kept in
/// the order first asked for, the last one found cached. A new block is value-initialised.
template <typename Block>
class BlockTable {
 public:
  /// The block of `origin`, made if missing.
  Block& BlockOf(std::uint64_t origin) {
    if (origin == last_origin_) return blocks_[last_];
    if (2 * (blocks_.size() + 1) > slots_.size()) Rehash();
    std::size_t i = Home(origin);
    for (;; i = (i + 1) & (slots_.size() - 1)) {
      const std::uint32_t s = slots_[i];
      if (s == 0) break;
      if (blocks_[s - 1].origin == origin) {
        last_origin_ = origin;
        last_ = s - 1;
        return blocks_[last_];
      }
    }
    blocks_.emplace_back();
    blocks_.back().origin = origin;
    slots_[i] = static_cast<std::uint32_t>(blocks_.size());
    last_origin_ = origin;
    last_ = blocks_.size() - 1;
    return blocks_.back();
  }
  /// The block of `origin`, or nullptr.
  [[nodiscard]] const Block* Find(std::uint64_t origin) const {
    if (slots_.empty()) return nullptr;
    for (std::size_t i = Home(origin);; i = (i + 1) & (slots_.size() - 1)) {
      const std::uint32_t s = slots_[i];
      if (s == 0) return nullptr;
      if (blocks_[s - 1].origin == origin) return &blocks_[s - 1];
    }
  }
  [[nodiscard]] std::span<const Block> blocks() const { return blocks_; }
  [[nodiscard]] std::span<Block> blocks() { return blocks_; }
  /// Empties the table, keeping its room.
  void clear() {
    std::fill(slots_.begin(), slots_.end(), 0u);
    blocks_.clear();
    last_origin_ = ~std::uint64_t{0};
  }

 private:
  [[nodiscard]] std::size_t Home(std::uint64_t origin) const {
    return static_cast<std::size_t>((origin * 0x9e3779b97f4a7c15ULL) >> shift_);
  }
  void Rehash() {
    const std::size_t capacity = std::max<std::size_t>(64, 2 * slots_.size());
    slots_.assign(capacity, 0u);
    shift_ = 64 - static_cast<unsigned>(std::countr_zero(capacity));
    for (std::size_t b = 0; b < blocks_.size(); ++b) {
      std::size_t i = Home(blocks_[b].origin);
      while (slots_[i] != 0) i = (i + 1) & (capacity - 1);
      slots_[i] = static_cast<std::uint32_t>(b + 1);
    }
  }

  std::vector<std::uint32_t> slots_;  // block index + 1; 0: empty
  std::vector<Block> blocks_;
  unsigned shift_ = 64;
  std::uint64_t last_origin_ = ~std::uint64_t{0};
  std::size_t last_ = 0;
};

/// A set of OcTreeKeys as 8 × 8 × 8 blocks of bits (as Bonxai and OpenVDB keep their leaves):
/// a block per 8³ cells that holds any, found by its block coordinates in an open-addressing
/// table, a cell's bit at its Morton index within the block. A block's cells in bit order are
/// in octree (Morton) order, so a batch's cells come out sorted by sorting its blocks alone.
/// Inserting a key already present costs what inserting a new one does: no repeats filter needed.
/// Not thread-safe; the mapper gives each thread its own and merges them by block.
class BlockKeySet {
 public:
  struct Block {
    std::uint64_t origin = 0;  ///< the packed key (PackKey) of its cell whose x, y, z end in 000
    std::array<std::uint64_t, 8> bits{};  ///< bit i of word w: the cell of Morton index 64w + i
  };

  /// The cell's Morton index within its block (0-511): x, y, z's low three bits interleaved as
  /// MortonCode interleaves a key's.
  [[nodiscard]] static unsigned IndexInBlock(std::uint64_t packed) {
    static constexpr std::array<unsigned, 8> kSpread = {0, 1, 8, 9, 64, 65, 72, 73};
    return (kSpread[(packed >> 32) & 7] << 2) | (kSpread[(packed >> 16) & 7] << 1) |
           kSpread[packed & 7];
  }
  /// The packed key whose low three bits of x, y and z are cleared: its block's origin.
  static constexpr std::uint64_t kOriginMask = ~((std::uint64_t{7} << 32) | (7u << 16) | 7u);

  /// Inserts a packed key (PackKey).
  void insert_packed(std::uint64_t packed) {
    const unsigned index = IndexInBlock(packed);
    BlockOf(packed & kOriginMask).bits[index >> 6] |= std::uint64_t{1} << (index & 63);
  }
  void insert_packed(std::span<const std::uint64_t> keys) {
    for (const std::uint64_t packed : keys) insert_packed(packed);
  }
  bool insert(const octomap::OcTreeKey& key) {
    const std::uint64_t packed = PackKey(key);
    const unsigned index = IndexInBlock(packed);
    std::uint64_t& word = BlockOf(packed & kOriginMask).bits[index >> 6];
    const std::uint64_t bit = std::uint64_t{1} << (index & 63);
    const bool fresh = (word & bit) == 0;
    word |= bit;
    return fresh;
  }
  [[nodiscard]] bool contains(const octomap::OcTreeKey& key) const {
    const std::uint64_t packed = PackKey(key);
    const Block* block = table_.Find(packed & kOriginMask);
    if (block == nullptr) return false;
    const unsigned index = IndexInBlock(packed);
    return (block->bits[index >> 6] >> (index & 63)) & 1u;
  }

  /// The keys held: a count over the blocks.
  [[nodiscard]] std::size_t size() const {
    std::size_t count = 0;
    for (const Block& b : table_.blocks()) {
      for (const std::uint64_t w : b.bits) count += static_cast<std::size_t>(std::popcount(w));
    }
    return count;
  }
  [[nodiscard]] bool empty() const { return table_.blocks().empty(); }
  /// The blocks, in the order they were first touched.
  [[nodiscard]] std::span<const Block> blocks() const { return table_.blocks(); }

  /// Empties the set, keeping its tables' room.
  void clear() { table_.clear(); }
  /// Nothing: clear() keeps the tables' room, and how many blocks `count` keys take depends on
  /// where they lie. (The mapper reserves each set's last size after clearing it.)
  void reserve(std::size_t /*count*/) {}

  /// Calls `f(packed)` for each key: block by block, each block's in Morton order.
  template <typename F>
  void for_each_packed(F&& f) const {
    for (const Block& b : table_.blocks()) ForEachInBlock(b, f);
  }
  /// Calls `f(packed)` for each cell of block `b`, in Morton order.
  template <typename F>
  static void ForEachInBlock(const Block& b, F&& f) {
    for (unsigned w = 0; w < 8; ++w) {
      for (std::uint64_t bits = b.bits[w]; bits != 0; bits &= bits - 1) {
        f(KeyInBlock(b.origin, 64 * w + static_cast<unsigned>(std::countr_zero(bits))));
      }
    }
  }
  /// The packed key of Morton index `index` in the block at `origin`.
  [[nodiscard]] static std::uint64_t KeyInBlock(std::uint64_t origin, unsigned index) {
    auto compact = [](unsigned v) { return (v & 1) | ((v >> 2) & 2) | ((v >> 4) & 4); };
    return origin | (std::uint64_t{compact(index >> 2)} << 32) |
           (std::uint64_t{compact(index >> 1)} << 16) | compact(index);
  }

 private:
  Block& BlockOf(std::uint64_t origin) { return table_.BlockOf(origin); }

  BlockTable<Block> table_;
};

}  // namespace sonarbench::mapping
