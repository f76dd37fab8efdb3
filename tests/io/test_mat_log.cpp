#include <gtest/gtest.h>
#include <matio.h>
#include <zlib.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <numbers>
#include <set>
#include <string>
#include <tuple>
#include <vector>

#include "sonarbench/base/error.hpp"
#include "sonarbench/io/mat_log.hpp"
#include "sonarbench/sim/app/dataset_writer.hpp"
#include "sonarbench/sim/app/map_log.hpp"
#include "sonarbench/sim/app/scenario.hpp"
#include "sonarbench/sim/eval/score.hpp"
#include "sonarbench/sim/report/fidelity_report.hpp"
#include "sonarbench/sim/report/scenario_report.hpp"
#include "sonarbench/sim/sonar/simulation.hpp"
#include "sonarbench/sim/world/mesh.hpp"
#include "sonarbench/sim/world/scene.hpp"
#include "test_util.hpp"

namespace sonarbench {
namespace {

using test::RealLogPath;

using mapping::kDegToRad;

// Writes the real log's bytes, changed by `change`, to `path`.
void WriteChangedRealLog(const std::string& path,
                         const std::function<void(std::vector<char>&)>& change) {
  std::ifstream in(RealLogPath(), std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  change(bytes);
  std::ofstream(path, std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

TEST(MatLog, CorruptOrMissingFilesAreClearErrors) {
  test::TempDir dir;
  const std::string garbage = (dir.path() / "garbage.mat").string();
  std::ofstream(garbage) << "MATLAB 5.0 MAT-file, but not really";
  for (const std::string& path : {garbage, (dir.path() / "absent.mat").string()}) {
    try {
      (void)io::ReadMatLog(path);
      ADD_FAILURE() << "no error for " << path;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    }
  }
}

TEST(MatLog, TruncatedCopyOfTheRealLogIsAClearError) {
  REQUIRE_REAL_LOG();
  test::TempDir dir;
  const std::string cut = (dir.path() / "cut.mat").string();
  WriteChangedRealLog(cut, [](std::vector<char>& bytes) { bytes.resize(bytes.size() / 2); });
  EXPECT_THROW((void)io::ReadMatLog(cut), InputError);
}

// One byte changed inside the compressed log, found by flipping bytes: at offset 299 libmatio sized
// parsedData's table of fields at 571 GB, left it unallocated and then read through a null pointer
// (segfault); at 620834 it allocated 13 GB over 35 s before it refused the file. Both break the
// compressed stream's checksum, which libmatio checks only at the end: refused at once now.
TEST(MatLog, CorruptCopiesOfTheRealLogAreClearErrors) {
  REQUIRE_REAL_LOG();
  test::TempDir dir;
  for (const auto& change : {std::tuple{299, 140, 165}, std::tuple{620834, 151, 252}}) {
    const int at = std::get<0>(change), before = std::get<1>(change), after = std::get<2>(change);
    const std::string bad = (dir.path() / ("bad" + std::to_string(at) + ".mat")).string();
    WriteChangedRealLog(bad, [&](std::vector<char>& bytes) {
      ASSERT_EQ(static_cast<unsigned char>(bytes.at(at)), before);
      bytes[at] = static_cast<char>(after);
    });
    EXPECT_EQ(test::InputErrorOf([&] { (void)io::ReadMatLog(bad); }),
              bad + ": a corrupt MAT file (a compressed element does not inflate whole)");
  }
}

// The check before libmatio reads what libmatio writes: a char array (whose stated size counts
// padding it leaves out of the compressed stream), an uncompressed array and the struct array of
// beams, compressed and not.
TEST(MatLog, WhatLibmatioWritesIsRead) {
  test::TempDir dir;
  for (const matio_compression compression : {MAT_COMPRESSION_ZLIB, MAT_COMPRESSION_NONE}) {
    const std::string path = (dir.path() / "written.mat").string();
    mat_t* mat = Mat_CreateVer(path.c_str(), nullptr, MAT_FT_MAT5);
    ASSERT_NE(mat, nullptr);
    std::size_t note_dims[2] = {1, 7};
    char note[] = "odd one";
    matvar_t* var = Mat_VarCreate("note", MAT_C_CHAR, MAT_T_UINT8, 2, note_dims, note, 0);
    Mat_VarWrite(mat, var, MAT_COMPRESSION_ZLIB);
    Mat_VarFree(var);
    std::size_t plain_dims[2] = {1, 3};
    double plain[3] = {1, 2, 3};
    var = Mat_VarCreate("plain", MAT_C_DOUBLE, MAT_T_DOUBLE, 2, plain_dims, plain, 0);
    Mat_VarWrite(mat, var, MAT_COMPRESSION_NONE);
    Mat_VarFree(var);
    const char* fields[4] = {"time", "angle", "step_dist", "intensities"};
    std::size_t beams[2] = {1, 2};
    matvar_t* data = Mat_VarCreateStruct("parsedData", 2, beams, fields, 4);
    for (std::size_t i = 0; i < 2; ++i) {
      std::size_t one[2] = {1, 1};
      std::size_t bins[2] = {1, 5};
      double time = 0.1 * static_cast<double>(i), angle = 1.8 * static_cast<double>(i);
      double step = 0.0125;
      double intensities[5] = {0, 10, 20, 30, 255};
      const auto set = [&](const char* field, std::size_t* dims, double* values) {
        Mat_VarSetStructFieldByName(
            data, field, i, Mat_VarCreate(nullptr, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, dims, values, 0));
      };
      set("time", one, &time);
      set("angle", one, &angle);
      set("step_dist", one, &step);
      set("intensities", bins, intensities);
    }
    Mat_VarWrite(mat, data, compression);
    Mat_VarFree(data);
    Mat_Close(mat);
    const io::MatLog log = io::ReadMatLog(path);
    ASSERT_EQ(log.beams.size(), 2u);
    EXPECT_EQ(log.beams[1].intensities, (std::vector<std::uint8_t>{0, 10, 20, 30, 255}));
    EXPECT_DOUBLE_EQ(log.beams[1].head_angle_rad, 1.8 * std::numbers::pi / 180.0);
  }
}

// A v5 log is read without libmatio: every beam as libmatio reads it from the real log.
TEST(MatLog, TheRealLogReadsAsLibmatioReadsIt) {
  REQUIRE_REAL_LOG();
  const io::MatLog log = io::ReadMatLog(RealLogPath());
  mat_t* mat = Mat_Open(RealLogPath().c_str(), MAT_ACC_RDONLY);
  ASSERT_NE(mat, nullptr);
  matvar_t* data = Mat_VarRead(mat, "parsedData");
  ASSERT_NE(data, nullptr);
  const std::size_t count = data->dims[0] * data->dims[1];
  ASSERT_EQ(log.beams.size(), count);
  auto number = [&](std::size_t i, const char* field) {
    const matvar_t* var = Mat_VarGetStructFieldByName(data, field, i);
    switch (var->class_type) {  // the classes the log holds
      case MAT_C_DOUBLE:
        return *static_cast<const double*>(var->data);
      case MAT_C_SINGLE:
        return static_cast<double>(*static_cast<const float*>(var->data));
      case MAT_C_UINT32:
        return static_cast<double>(*static_cast<const std::uint32_t*>(var->data));
      default:
        ADD_FAILURE() << field << " of class " << var->class_type;
        return 0.0;
    }
  };
  for (std::size_t i = 0; i < count; ++i) {
    const matvar_t* bins = Mat_VarGetStructFieldByName(data, "intensities", i);
    ASSERT_EQ(bins->class_type, MAT_C_DOUBLE);
    const auto* values = static_cast<const double*>(bins->data);
    const std::vector<std::uint8_t> expected(values, values + bins->nbytes / sizeof(double));
    ASSERT_EQ(log.beams[i].intensities, expected) << "beam " << i;
    ASSERT_EQ(log.beams[i].time_s, number(i, "time")) << "beam " << i;
    ASSERT_EQ(log.beams[i].head_angle_rad, number(i, "angle") * kDegToRad) << "beam " << i;
    ASSERT_EQ(log.beams[i].bin_size_m, number(i, "step_dist")) << "beam " << i;
  }
  Mat_VarFree(data);
  Mat_Close(mat);
}

// Writes a v5 log of one beam per entry of `intensities` (a class each), with the fields named.
void WriteLog(const std::string& path, const std::vector<matvar_t*>& intensities,
              std::vector<const char*> fields = {"time", "angle", "step_dist", "intensities"}) {
  mat_t* mat = Mat_CreateVer(path.c_str(), nullptr, MAT_FT_MAT5);
  std::size_t beams[2] = {1, intensities.size()};
  matvar_t* data = Mat_VarCreateStruct("parsedData", 2, beams, fields.data(), fields.size());
  for (std::size_t i = 0; i < intensities.size(); ++i) {
    std::size_t one[2] = {1, 1};
    float time = 0.25F * static_cast<float>(i);  // a single
    std::int16_t angle = static_cast<std::int16_t>(-90 + 45 * static_cast<int>(i));
    double step = 0.0125;
    for (const char* field : fields) {
      const std::string name = field;
      matvar_t* value =
          name == "time"    ? Mat_VarCreate(nullptr, MAT_C_SINGLE, MAT_T_SINGLE, 2, one, &time, 0)
          : name == "angle" ? Mat_VarCreate(nullptr, MAT_C_INT16, MAT_T_INT16, 2, one, &angle, 0)
          : name == "step_dist"
              ? Mat_VarCreate(nullptr, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, one, &step, 0)
              : Mat_VarDuplicate(intensities[i], 1);
      Mat_VarSetStructFieldByName(data, field, i, value);
    }
  }
  Mat_VarWrite(mat, data, MAT_COMPRESSION_ZLIB);
  Mat_VarFree(data);
  Mat_Close(mat);
  for (matvar_t* var : intensities) Mat_VarFree(var);
}

TEST(MatLog, FieldsOfAnyRealNumericClassAreRead) {
  test::TempDir dir;
  const std::string path = (dir.path() / "classes.mat").string();
  std::size_t three[2] = {1, 3};
  std::uint8_t u8[3] = {0, 128, 255};
  std::int16_t i16[3] = {1, 2, 255};
  float single[3] = {3, 4, 5};
  WriteLog(path, {Mat_VarCreate(nullptr, MAT_C_UINT8, MAT_T_UINT8, 2, three, u8, 0),
                  Mat_VarCreate(nullptr, MAT_C_INT16, MAT_T_INT16, 2, three, i16, 0),
                  Mat_VarCreate(nullptr, MAT_C_SINGLE, MAT_T_SINGLE, 2, three, single, 0)});
  const io::MatLog log = io::ReadMatLog(path);
  ASSERT_EQ(log.beams.size(), 3u);
  EXPECT_EQ(log.beams[0].intensities, (std::vector<std::uint8_t>{0, 128, 255}));
  EXPECT_EQ(log.beams[1].intensities, (std::vector<std::uint8_t>{1, 2, 255}));
  EXPECT_EQ(log.beams[2].intensities, (std::vector<std::uint8_t>{3, 4, 5}));
  EXPECT_EQ(log.beams[2].time_s, 0.5);
  EXPECT_DOUBLE_EQ(log.beams[0].head_angle_rad, -std::numbers::pi / 2.0);
  EXPECT_DOUBLE_EQ(log.beams[1].head_angle_rad, -std::numbers::pi / 4.0);
}

TEST(MatLog, AFieldMissingOrOutOfRangeIsNamedWithItsBeam) {
  test::TempDir dir;
  const std::string path = (dir.path() / "bad.mat").string();
  std::size_t two[2] = {1, 2};
  std::uint16_t high[2] = {255, 256};
  std::int64_t wide[2] = {1, 2};
  double low[2] = {1.0, 2.0};
  auto u16 = [&] { return Mat_VarCreate(nullptr, MAT_C_UINT16, MAT_T_UINT16, 2, two, high, 0); };
  WriteLog(path, {Mat_VarCreate(nullptr, MAT_C_DOUBLE, MAT_T_DOUBLE, 2, two, low, 0), u16()});
  EXPECT_EQ(test::InputErrorOf([&] { (void)io::ReadMatLog(path); }),
            path + ": beam 1, field 'intensities', bin 1: expected an integer in 0..255");
  WriteLog(path, {Mat_VarCreate(nullptr, MAT_C_INT64, MAT_T_INT64, 2, two, wide, 0)});
  EXPECT_EQ(test::InputErrorOf([&] { (void)io::ReadMatLog(path); }),
            path + ": beam 0, field 'intensities', bin 0: expected an integer in 0..255");
  WriteLog(path, {u16()}, {"time", "step_dist", "intensities"});
  EXPECT_EQ(test::InputErrorOf([&] { (void)io::ReadMatLog(path); }),
            path + ": beam 0, field 'angle': missing");
}

// A struct array without fields holds no values whatever its dimensions say: refused before the
// beams are sized by them (a fuzzer's input asked for 2e11 bytes).
TEST(MatLog, AStructArrayWithoutFieldsIsRefused) {
  test::TempDir dir;
  const std::string path = (dir.path() / "fieldless.mat").string();
  mat_t* mat = Mat_CreateVer(path.c_str(), nullptr, MAT_FT_MAT5);
  std::size_t beams[2] = {1, 2000000000};
  matvar_t* data = Mat_VarCreateStruct("parsedData", 2, beams, nullptr, 0);
  Mat_VarWrite(mat, data, MAT_COMPRESSION_ZLIB);
  Mat_VarFree(data);
  Mat_Close(mat);
  EXPECT_EQ(
      test::InputErrorOf([&] { (void)io::ReadMatLog(path); }),
      path + ": 'parsedData' has no fields (expected time, angle, step_dist and intensities)");
}

// Only a little-endian v5 or v7.3 header reaches libmatio: it read a v4 variable's name length
// from the first bytes of this file (the start of a v5 header moved 18 bytes) and asked for 1 GB.
TEST(MatLog, AFileWithoutAV5OrV73HeaderNeverReachesLibmatio) {
  test::TempDir dir;
  std::string shifted(18, '\0');
  shifted += "MATLAB 5.0 MAT-file";
  shifted.resize(164, ' ');
  const std::string path = test::WriteFile(dir, "shifted.mat", shifted);
  EXPECT_EQ(test::InputErrorOf([&] { (void)io::ReadMatLog(path); }),
            path +
                ": not a MAT v5 or v7.3 file (no MAT header in its first 128 bytes; expected "
                "the .mat log of pings)");
  std::string big_endian(128, ' ');
  big_endian.replace(0, 10, "MATLAB 5.0");
  big_endian.replace(124, 4, std::string("\x01\0MI", 4));
  test::WriteFile(dir, "shifted.mat", big_endian);
  EXPECT_EQ(test::InputErrorOf([&] { (void)io::ReadMatLog(path); }),
            path + ": a big-endian MAT file (expected a little-endian v5 or v7.3 .mat log)");
}

// A MAT v5 file whose array states more elements than it holds values is refused before libmatio
// reads it (it would allocate what the dimensions say: 16 GB here).
TEST(MatLog, AnArrayLargerThanItsBytesIsRefused) {
  test::TempDir dir;
  std::string mat(116, ' ');
  mat.replace(0, 10, "MATLAB 5.0");
  mat += std::string(8, '\0') + std::string("\x00\x01IM", 4);
  const auto u32 = [&](std::uint32_t value) {
    mat.append(reinterpret_cast<const char*>(&value), 4);  // little-endian, as "IM" says
  };
  u32(14), u32(72);                         // miMATRIX of 72 bytes
  u32(6), u32(8), u32(6), u32(0);           // its flags: a double array
  u32(5), u32(8), u32(1), u32(2000000000);  // 1 x 2e9
  u32(1), u32(10), mat += std::string("parsedData\0\0\0\0\0\0", 16);
  u32(9), u32(8), mat += std::string("\0\0\0\0\0\0\xf0\x3f", 8);  // one double, 1.0
  const std::string path = test::WriteFile(dir, "huge.mat", mat);
  EXPECT_EQ(
      test::InputErrorOf([&] { (void)io::ReadMatLog(path); }),
      path + ": a corrupt MAT file (an array of 2000000000 elements holds 8 bytes of values)");
  // A sparse array is refused before libmatio sizes it by its nonzero count.
  std::string sparse = mat;
  sparse[128 + 8 + 8] = '\x05';
  test::WriteFile(dir, "huge.mat", sparse);
  EXPECT_EQ(test::InputErrorOf([&] { (void)io::ReadMatLog(path); }),
            path +
                ": a corrupt MAT file (an array of class 5 (expected cell, struct, char or "
                "numeric arrays))");
  // A char array's values are checked as a numeric array's are: libmatio sizes them by their tag.
  std::string chars = mat;
  chars[128 + 8 + 8] = '\x04';
  chars.replace(128 + 8 + 16 + 8 + 4, 4, std::string("\x02\0\0\0", 4));  // 1 x 2 characters
  chars.replace(128 + 8 + 16 + 16 + 24, 8, std::string("\x05\0\0\0\0\0\0\x6c", 8));
  test::WriteFile(dir, "huge.mat", chars);
  EXPECT_EQ(test::InputErrorOf([&] { (void)io::ReadMatLog(path); }),
            path + ": a corrupt MAT file (an element states 1811939328 bytes where 8 are left)");
  // The same file stating the one element it holds is read as far as its layout: not a struct.
  mat.replace(128 + 8 + 16 + 8 + 4, 4, std::string("\x01\0\0\0", 4));
  test::WriteFile(dir, "huge.mat", mat);
  EXPECT_EQ(test::InputErrorOf([&] { (void)io::ReadMatLog(path); }),
            path + ": 'parsedData' is not a struct array");
}

// A compressed element is measured before it is inflated: one that inflates past what is left of
// the budget (after the file's own bytes) is refused; the same file under a budget that holds it
// is read on to its layout.
TEST(MatLog, ACompressedElementPastTheBudgetIsRefusedBeforeItIsInflated) {
  test::TempDir dir;
  std::string mat(116, ' ');
  mat.replace(0, 10, "MATLAB 5.0");
  mat += std::string(8, '\0') + std::string("\x00\x01IM", 4);
  const std::string zeros(4 << 20, '\0');
  std::string packed(compressBound(zeros.size()), '\0');
  uLongf packed_size = packed.size();
  ASSERT_EQ(compress(reinterpret_cast<Bytef*>(packed.data()), &packed_size,
                     reinterpret_cast<const Bytef*>(zeros.data()), zeros.size()),
            Z_OK);
  packed.resize(packed_size);
  const std::uint32_t tag[2] = {15, static_cast<std::uint32_t>(packed.size())};  // miCOMPRESSED
  mat.append(reinterpret_cast<const char*>(tag), 8);
  mat += packed;
  const std::string path = test::WriteFile(dir, "bomb.mat", mat);
  EXPECT_TRUE(test::ThrowsInputErrorWith(
      [&] { (void)io::ReadMatLog(path, std::uint64_t{2} << 20); },
      {"bomb.mat: a corrupt MAT file (its compressed elements inflate to more than the"}));
  EXPECT_FALSE(test::InputErrorOf([&] {
                 (void)io::ReadMatLog(path, std::uint64_t{8} << 20);
               }).find("inflate to more than") != std::string::npos);
  EXPECT_TRUE(test::ThrowsInputErrorWith(
      [&] { (void)io::ReadMatLog(path, 1000); },
      {"bomb.mat: holds", "more than the 1000 bytes sonarbench reads from such a file"}));
}

}  // namespace
}  // namespace sonarbench
