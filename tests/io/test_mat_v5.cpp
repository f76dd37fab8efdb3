#include <gtest/gtest.h>

#include <cstdint>
#include <string_view>

#include "mat_v5.hpp"

namespace sonarbench::io::mat_v5 {
namespace {

// StoredBytes hands out uint8-stored values exactly when NumericAt reads each of them back as
// that byte, whatever the array's class says: for int8 it declines (NumericAt refuses 128..255).
TEST(MatV5, StoredBytesAreWhatNumericAtReadsOrNothing) {
  const char bytes[] = {0, 1, 127, static_cast<char>(128), static_cast<char>(255)};
  constexpr std::uint32_t kUint8 = 2, kInt8 = 1, kDouble = 9;
  for (std::uint32_t array_class = 1; array_class <= 15; ++array_class) {
    for (const std::uint32_t data_type : {kUint8, kInt8, kDouble}) {
      const ArrayView view{array_class, false, 5, data_type, bytes, sizeof bytes};
      const std::string_view stored = view.StoredBytes();
      bool all_read = data_type == kUint8;
      for (std::size_t k = 0; k < 5 && all_read; ++k) {
        all_read = view.NumericAt(k) == static_cast<double>(static_cast<unsigned char>(bytes[k]));
      }
      EXPECT_EQ(stored.size(), all_read ? 5u : 0u) << array_class << " " << data_type;
      if (!stored.empty()) {
        EXPECT_EQ(stored, std::string_view(bytes, 5));
      }
    }
  }
  const ArrayView complex{6, true, 5, kUint8, bytes, sizeof bytes};
  EXPECT_TRUE(complex.StoredBytes().empty());
  const ArrayView short_of_bytes{6, false, 6, kUint8, bytes, sizeof bytes};
  EXPECT_TRUE(short_of_bytes.StoredBytes().empty());
  EXPECT_FALSE(short_of_bytes.NumericAt(5).has_value());
}

}  // namespace
}  // namespace sonarbench::io::mat_v5
