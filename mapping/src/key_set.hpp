#pragma once

#include <octomap/OcTreeKey.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>
#include <span>
#include <utility>
#include <vector>

namespace sonarbench::mapping {

/// An OcTreeKey packed into 48 bits of a 64-bit integer: x in bits 32-47, y in 16-31, z in 0-15.
[[nodiscard]] inline std::uint64_t PackKey(const octomap::OcTreeKey& key) {
  return (static_cast<std::uint64_t>(key[0]) << 32) | (static_cast<std::uint64_t>(key[1]) << 16) |
         static_cast<std::uint64_t>(key[2]);
}
[[nodiscard]] inline octomap::OcTreeKey UnpackKey(std::uint64_t packed) {
  return {static_cast<octomap::key_type>(packed >> 32),
          static_cast<octomap::key_type>((packed >> 16) & 0xffff),
          static_cast<octomap::key_type>(packed & 0xffff)};
}

/// The key's Morton code: the bits of x, y and z interleaved, most significant first, which is
/// the order of a depth-first walk of the octree.
[[nodiscard]] inline std::uint64_t MortonCode(const octomap::OcTreeKey& key) {
  auto spread = [](std::uint64_t v) {  // 16 bits to every third of 48
    v = (v | (v << 16)) & 0x0000ff0000ffULL;
    v = (v | (v << 8)) & 0x00f00f00f00fULL;
    v = (v | (v << 4)) & 0x0c30c30c30c3ULL;
    v = (v | (v << 2)) & 0x249249249249ULL;
    return v;
  };
  return (spread(key[0]) << 2) | (spread(key[1]) << 1) | spread(key[2]);
}

/// The key whose Morton code is `code` (the inverse of MortonCode).
[[nodiscard]] inline octomap::OcTreeKey KeyFromMortonCode(std::uint64_t code) {
  auto compact = [](std::uint64_t v) {  // every third of 48 bits to 16
    v &= 0x249249249249ULL;
    v = (v | (v >> 2)) & 0x0c30c30c30c3ULL;
    v = (v | (v >> 4)) & 0x00f00f00f00fULL;
    v = (v | (v >> 8)) & 0x0000ff0000ffULL;
    v = (v | (v >> 16)) & 0x00000000ffffULL;
    return static_cast<octomap::key_type>(v);
  };
  return {compact(code >> 2), compact(code >> 1), compact(code)};
}

/// Collision resolution of the open-addressing set (the seed paper, section 2.2).
enum class Probing {
  kLinear,     ///< h, h+1, h+2, ...
  kQuadratic,  ///< h + (i² + i)/2: visits every slot of a power-of-two table (2.2.2)
  kDouble,     ///< h + i·s with an odd step s from other hash bits: also visits every slot (2.2.3)
};

/// How the table grows when it passes its load factor (the seed paper, section 2.3).
enum class Resize {
  kAllAtOnce,  ///< allocate a table twice the size and reinsert everything into it
  kInPlace,    ///< grow the allocation (realloc: mremap for large tables, no copy) and rehash in it
};

/// A hash set of OcTreeKeys with open addressing (the seed paper's section 2, done over):
/// keys are stored as raw packed 64-bit values, no node per key; the table is a power of two and
/// indexed with a mask; the hash is a Fibonacci multiply whose top bits are taken, so all 48 key
/// bits reach the index (OctoMap's own KeyHash mixes the low bits of x and y poorly); erased
/// keys leave tombstones, and an insert looks past them for the key before reusing one, so
/// there is never a duplicate; `CacheHash` keeps each slot's hash beside it, so a resize does
/// not recompute it.
///
/// Not thread-safe; the mapper gives each thread its own set and merges them.
template <Probing kProbing = Probing::kQuadratic, Resize kResize = Resize::kInPlace,
          bool kCacheHash = false>
class OpenKeySet {
 public:
  OpenKeySet() = default;
  explicit OpenKeySet(std::size_t expected) { reserve(expected); }
  ~OpenKeySet() { Release(); }
  OpenKeySet(const OpenKeySet& other) { *this = other; }
  OpenKeySet& operator=(const OpenKeySet& other) {
    if (this == &other) return *this;
    Release();
    Allocate(other.capacity_);
    if (capacity_ > 0) {
      std::memcpy(slots_, other.slots_, capacity_ * sizeof(std::uint64_t));
      if constexpr (kCacheHash)
        std::memcpy(hashes_, other.hashes_, capacity_ * sizeof(std::uint64_t));
    }
    size_ = other.size_;
    tombstones_ = other.tombstones_;
    return *this;
  }
  OpenKeySet(OpenKeySet&& other) noexcept { Swap(other); }
  OpenKeySet& operator=(OpenKeySet&& other) noexcept {
    OpenKeySet moved(std::move(other));
    Swap(moved);
    return *this;
  }

  /// Inserts `key`; returns false if it was already present.
  bool insert(const octomap::OcTreeKey& key) { return InsertPacked(PackKey(key)); }
  /// Inserts a key already packed with PackKey.
  bool insert_packed(std::uint64_t packed) { return InsertPacked(packed); }
  /// Inserts keys already packed, fetching each one's home slot into the cache a few keys
  /// ahead, so that the misses of a large table overlap instead of waiting in turn.
  void insert_packed(std::span<const std::uint64_t> keys) {
    constexpr std::size_t kAhead = 8;
    for (std::size_t i = 0; i < keys.size(); ++i) {
      if (i + kAhead < keys.size() && capacity_ > 0) {
        __builtin_prefetch(slots_ + Home(Hash(keys[i + kAhead])), 1);
      }
      InsertPacked(keys[i]);
    }
  }
  template <typename It>
  void insert(It first, It last) {
    for (; first != last; ++first) InsertPacked(PackKey(*first));
  }
  [[nodiscard]] bool contains(const octomap::OcTreeKey& key) const {
    return FindPacked(PackKey(key)) != kNotFound;
  }
  /// Removes `key`, leaving a tombstone; returns false if it was absent.
  bool erase(const octomap::OcTreeKey& key) {
    const std::size_t slot = FindPacked(PackKey(key));
    if (slot == kNotFound) return false;
    Bury(slot);
    return true;
  }

  /// Inserts every key of `other`. Reserves first for the pessimistic case that no key is shared
  /// (section 2.4.4), so at most one resize happens.
  void merge(const OpenKeySet& other) {
    reserve(size_ + other.size_);
    other.ForEachPacked(
        [this](std::uint64_t packed, std::uint64_t hash) { InsertHashed(packed, hash); });
  }
  /// The same merge without the reserve, for measuring what the reserve saves.
  void merge_without_reserve(const OpenKeySet& other) {
    other.ForEachPacked(
        [this](std::uint64_t packed, std::uint64_t hash) { InsertHashed(packed, hash); });
  }
  /// Removes every key that `other` holds.
  void difference(const OpenKeySet& other) {
    if (other.size_ < size_) {
      other.ForEachPacked([this](std::uint64_t packed, std::uint64_t) {
        const std::size_t slot = FindPacked(packed);
        if (slot != kNotFound) Bury(slot);
      });
    } else {
      for (std::size_t i = 0; i < capacity_; ++i) {
        if (IsKey(slots_[i]) && other.FindPacked(slots_[i]) != kNotFound) Bury(i);
      }
    }
  }

  /// Makes room for `count` keys without a resize.
  void reserve(std::size_t count) {
    const std::size_t needed = CapacityFor(count + tombstones_);
    if (needed > capacity_) Grow(needed);
  }
  void clear() {
    if (capacity_ > 0) std::memset(slots_, 0xff, capacity_ * sizeof(std::uint64_t));
    size_ = 0;
    tombstones_ = 0;
  }

  [[nodiscard]] std::size_t size() const { return size_; }
  [[nodiscard]] bool empty() const { return size_ == 0; }
  [[nodiscard]] std::size_t capacity() const { return capacity_; }
  /// Probes that landed on another key, since construction (the paper's figure 3).
  [[nodiscard]] std::uint64_t collisions() const { return collisions_; }
  /// The most bytes the set's tables held at once, counting both tables during a resize.
  [[nodiscard]] std::size_t peak_bytes() const { return peak_bytes_; }

  /// Iterates the keys in table order; any insert or erase invalidates iterators.
  class const_iterator {
   public:
    using value_type = octomap::OcTreeKey;
    using difference_type = std::ptrdiff_t;
    const_iterator() = default;
    octomap::OcTreeKey operator*() const { return UnpackKey(set_->slots_[slot_]); }
    const_iterator& operator++() {
      ++slot_;
      Skip();
      return *this;
    }
    const_iterator operator++(int) {
      const_iterator before = *this;
      ++*this;
      return before;
    }
    bool operator==(const const_iterator& other) const { return slot_ == other.slot_; }

   private:
    friend class OpenKeySet;
    const_iterator(const OpenKeySet* set, std::size_t slot) : set_(set), slot_(slot) { Skip(); }
    void Skip() {
      while (slot_ < set_->capacity_ && !IsKey(set_->slots_[slot_])) ++slot_;
    }
    const OpenKeySet* set_ = nullptr;
    std::size_t slot_ = 0;
  };
  [[nodiscard]] const_iterator begin() const { return const_iterator(this, 0); }
  [[nodiscard]] const_iterator end() const { return const_iterator(this, capacity_); }

  /// Calls `f(packed)` for every key, packed, in table order: eight slots at a time, their
  /// occupancy gathered into a bit mask without a branch per slot (a table at most half full
  /// would otherwise mispredict about every other slot).
  template <typename F>
  void for_each_packed(F&& f) const {
    constexpr std::size_t kBlock = 8;  // capacities are powers of two, at least 16
    for (std::size_t i = 0; i < capacity_; i += kBlock) {
      unsigned occupied = 0;
      for (std::size_t j = 0; j < kBlock; ++j) {
        occupied |= static_cast<unsigned>(IsKey(slots_[i + j])) << j;
      }
      while (occupied != 0) {
        f(slots_[i + static_cast<std::size_t>(std::countr_zero(occupied))]);
        occupied &= occupied - 1;
      }
    }
  }

 private:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};
  static constexpr std::uint64_t kTombstone = kEmpty - 1;  // packed keys stay below 2^48
  static constexpr std::size_t kNotFound = ~std::size_t{0};
  static constexpr std::size_t kMinCapacity = 16;
  // Grow past 1/2 full (tombstones included): quadratic probing in a power-of-two table stays
  // short below that, and linear probing's clusters are still small.
  static constexpr std::size_t kLoadNumerator = 1;
  static constexpr std::size_t kLoadDenominator = 2;

  static bool IsKey(std::uint64_t slot) { return slot < kTombstone; }
  // Erases the key in `slot`, leaving a tombstone so that probe paths through it stay whole.
  void Bury(std::size_t slot) {
    slots_[slot] = kTombstone;
    --size_;
    ++tombstones_;
  }
  static std::uint64_t Hash(std::uint64_t packed) { return packed * 0x9e3779b97f4a7c15ULL; }
  static std::size_t CapacityFor(std::size_t count) {
    const std::size_t min_slots = count * kLoadDenominator / kLoadNumerator + 1;
    return std::max(kMinCapacity, std::bit_ceil(min_slots));
  }

  std::size_t Home(std::uint64_t hash) const { return static_cast<std::size_t>(hash >> shift_); }
  // The i-th probe after `home`; `step` is the double-hashing stride.
  std::size_t Probe(std::size_t home, std::size_t i, std::size_t step) const {
    if constexpr (kProbing == Probing::kLinear) return (home + i) & mask_;
    if constexpr (kProbing == Probing::kQuadratic) return (home + (i * i + i) / 2) & mask_;
    return (home + i * step) & mask_;
  }
  // A second, independent multiply of the key, recovered from the first hash (the golden-ratio
  // multiplier is odd, so invertible); odd, so coprime with the power-of-two table size.
  static std::size_t Step(std::uint64_t hash) {
    return static_cast<std::size_t>(((hash * 0xc2b2ae3d27d4eb4fULL) >> 32) | 1);
  }

  std::size_t FindPacked(std::uint64_t packed) const {
    if (capacity_ == 0) return kNotFound;
    const std::uint64_t hash = Hash(packed);
    const std::size_t home = Home(hash);
    const std::size_t step = Step(hash);
    for (std::size_t i = 0; i < capacity_; ++i) {
      const std::size_t slot = Probe(home, i, step);
      if (slots_[slot] == packed) return slot;
      if (slots_[slot] == kEmpty) return kNotFound;
    }
    return kNotFound;
  }

  bool InsertPacked(std::uint64_t packed) { return InsertHashed(packed, Hash(packed)); }

  bool InsertHashed(std::uint64_t packed, std::uint64_t hash) {
    if ((size_ + tombstones_ + 1) * kLoadDenominator > capacity_ * kLoadNumerator) {
      Grow(CapacityFor(size_ + 1));
    }
    const std::size_t home = Home(hash);
    const std::size_t step = Step(hash);
    std::size_t reuse = kNotFound;
    for (std::size_t i = 0;; ++i) {
      const std::size_t slot = Probe(home, i, step);
      const std::uint64_t value = slots_[slot];
      if (value == packed) return false;
      if (value == kEmpty) {
        const std::size_t target = reuse != kNotFound ? reuse : slot;
        if (reuse != kNotFound) --tombstones_;
        slots_[target] = packed;
        if constexpr (kCacheHash) hashes_[target] = hash;
        ++size_;
        return true;
      }
      if (value == kTombstone) {
        if (reuse == kNotFound) reuse = slot;  // but keep looking: the key may lie further on
      } else {
        ++collisions_;
      }
    }
  }

  template <typename F>
  void ForEachPacked(F&& f) const {
    for (std::size_t i = 0; i < capacity_; ++i) {
      if (IsKey(slots_[i])) f(slots_[i], kCacheHash ? hashes_[i] : Hash(slots_[i]));
    }
  }

  void Grow(std::size_t new_capacity) {
    new_capacity = std::max(new_capacity, capacity_);  // a rebuild may only drop tombstones
    if constexpr (kResize == Resize::kAllAtOnce) {
      OpenKeySet bigger;
      bigger.Allocate(new_capacity);
      bigger.collisions_ = collisions_;
      peak_bytes_ = std::max(peak_bytes_, Bytes(capacity_) + Bytes(new_capacity));
      ForEachPacked(
          [&](std::uint64_t packed, std::uint64_t hash) { bigger.PlaceNew(packed, hash); });
      bigger.peak_bytes_ = peak_bytes_;
      Swap(bigger);
    } else {
      GrowInPlace(new_capacity);
    }
  }

  // Places a key known to be absent, into a table with no tombstones.
  void PlaceNew(std::uint64_t packed, std::uint64_t hash) {
    const std::size_t home = Home(hash);
    const std::size_t step = Step(hash);
    for (std::size_t i = 0;; ++i) {
      const std::size_t slot = Probe(home, i, step);
      if (slots_[slot] == kEmpty) {
        slots_[slot] = packed;
        if constexpr (kCacheHash) hashes_[slot] = hash;
        ++size_;
        return;
      }
      ++collisions_;
    }
  }

  // Section 2.3.1, done so that no probe path is ever broken: the table is extended (realloc,
  // which for large tables remaps pages instead of copying), tombstones are dropped, and every
  // old key is moved to its new place. A key whose new place holds a key not yet moved swaps
  // with it and carries that one on; moved keys never move again, so each moved key's probe
  // path runs only over moved keys and no hole can open in it.
  void GrowInPlace(std::size_t new_capacity) {
    const std::size_t old_capacity = capacity_;
    Reallocate(new_capacity);
    std::vector<bool> moved(capacity_, false);
    for (std::size_t i = 0; i < old_capacity; ++i) {
      if (slots_[i] == kTombstone) slots_[i] = kEmpty;
    }
    tombstones_ = 0;
    for (std::size_t i = 0; i < old_capacity; ++i) {
      if (!IsKey(slots_[i]) || moved[i]) continue;
      std::uint64_t carry = slots_[i];
      std::uint64_t carry_hash = kCacheHash ? hashes_[i] : Hash(carry);
      slots_[i] = kEmpty;
      for (bool placed = false; !placed;) {
        const std::size_t home = Home(carry_hash);
        const std::size_t step = Step(carry_hash);
        for (std::size_t probe = 0;; ++probe) {
          const std::size_t slot = Probe(home, probe, step);
          if (slots_[slot] == kEmpty) {
            slots_[slot] = carry;
            if constexpr (kCacheHash) hashes_[slot] = carry_hash;
            moved[slot] = true;
            placed = true;
            break;
          }
          if (!moved[slot]) {
            std::swap(carry, slots_[slot]);
            if constexpr (kCacheHash)
              std::swap(carry_hash, hashes_[slot]);
            else
              carry_hash = Hash(carry);
            moved[slot] = true;
            break;  // carry the displaced key from its own home
          }
          ++collisions_;
        }
      }
    }
  }

  static std::size_t Bytes(std::size_t capacity) {
    return capacity * sizeof(std::uint64_t) * (kCacheHash ? 2 : 1);
  }

  void Allocate(std::size_t capacity) {
    SetCapacity(capacity);
    if (capacity == 0) return;
    slots_ = static_cast<std::uint64_t*>(std::malloc(capacity * sizeof(std::uint64_t)));
    if (slots_ == nullptr) throw std::bad_alloc();
    std::memset(slots_, 0xff, capacity * sizeof(std::uint64_t));
    if constexpr (kCacheHash) {
      hashes_ = static_cast<std::uint64_t*>(std::malloc(capacity * sizeof(std::uint64_t)));
      if (hashes_ == nullptr) throw std::bad_alloc();
    }
    peak_bytes_ = std::max(peak_bytes_, Bytes(capacity));
  }

  void Reallocate(std::size_t capacity) {
    auto* slots =
        static_cast<std::uint64_t*>(std::realloc(slots_, capacity * sizeof(std::uint64_t)));
    if (slots == nullptr) throw std::bad_alloc();
    slots_ = slots;
    std::memset(slots_ + capacity_, 0xff, (capacity - capacity_) * sizeof(std::uint64_t));
    if constexpr (kCacheHash) {
      auto* hashes =
          static_cast<std::uint64_t*>(std::realloc(hashes_, capacity * sizeof(std::uint64_t)));
      if (hashes == nullptr) throw std::bad_alloc();
      hashes_ = hashes;
    }
    SetCapacity(capacity);
    peak_bytes_ = std::max(peak_bytes_, Bytes(capacity));
  }

  // The table size and what derives from it: the index mask and the hash shift (the top
  // log2(capacity) bits of the hash index the table).
  void SetCapacity(std::size_t capacity) {
    capacity_ = capacity;
    mask_ = capacity > 0 ? capacity - 1 : 0;
    shift_ = capacity > 1 ? 64 - std::countr_zero(capacity) : 63;
  }

  void Release() {
    std::free(slots_);
    std::free(hashes_);
    slots_ = nullptr;
    hashes_ = nullptr;
    SetCapacity(0);
    size_ = 0;
    tombstones_ = 0;
  }

  void Swap(OpenKeySet& other) noexcept {
    std::swap(slots_, other.slots_);
    std::swap(hashes_, other.hashes_);
    std::swap(capacity_, other.capacity_);
    std::swap(mask_, other.mask_);
    std::swap(shift_, other.shift_);
    std::swap(size_, other.size_);
    std::swap(tombstones_, other.tombstones_);
    std::swap(collisions_, other.collisions_);
    std::swap(peak_bytes_, other.peak_bytes_);
  }

  std::uint64_t* slots_ = nullptr;
  std::uint64_t* hashes_ = nullptr;
  std::size_t capacity_ = 0;
  std::size_t mask_ = 0;
  int shift_ = 63;
  std::size_t size_ = 0;
  std::size_t tombstones_ = 0;
  std::uint64_t collisions_ = 0;
  std::size_t peak_bytes_ = 0;
};

/// The keys most recently inserted into one set, in a direct-mapped table small enough to stay
/// in the first-level cache: a key found here is in the set already, so its insert (a probe of
/// a table that may be megabytes) can be skipped; a key not found may or may not be in the set.
/// Neighbouring beams share most of their cells, so most repeats are caught here. Clear it
/// whenever its set is cleared.
class RecentKeys {
 public:
  RecentKeys() { clear(); }
  /// Whether `packed` was remembered; remembers it (evicting the key in its slot) if not.
  bool CheckAndRemember(std::uint64_t packed) {
    std::uint64_t& slot = slots_[(packed * 0x9e3779b97f4a7c15ULL) >> (64 - kBits)];
    if (slot == packed) return true;
    slot = packed;
    return false;
  }
  void clear() { slots_.fill(~std::uint64_t{0}); }  // no packed key is all ones

 private:
  static constexpr unsigned kBits = 12;  // 4096 keys, 32 KiB
  std::array<std::uint64_t, std::size_t{1} << kBits> slots_;
};

/// The set the mapper uses: quadratic probing (the paper's best) with all-at-once resize, which
/// pipeline_bench measures faster than in-place inside the mapper; in-place halves the peak
/// memory of a resize where that matters more (the paper's choice, for the vehicle's computer).
using KeyOpenSet = OpenKeySet<Probing::kQuadratic, Resize::kAllAtOnce, false>;

}  // namespace sonarbench::mapping
