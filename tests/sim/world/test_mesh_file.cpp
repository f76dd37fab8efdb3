#include <gtest/gtest.h>
#include <sys/stat.h>

#include <array>
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/sim/world/mesh.hpp"
#include "sonarbench/sim/world/mesh_file.hpp"
#include "test_util.hpp"

namespace sonarbench::sim {
namespace {

struct Box {
  Eigen::Vector3d lo, hi;
};

Box Bounds(const std::vector<Eigen::Vector3d>& vertices) {
  Box b{Eigen::Vector3d::Constant(1e9), Eigen::Vector3d::Constant(-1e9)};
  for (const auto& v : vertices) {
    b.lo = b.lo.cwiseMin(v);
    b.hi = b.hi.cwiseMax(v);
  }
  return b;
}

TriangleMesh AsMesh(const MeshFileData& data, const std::array<double, 3>& scale = {1, 1, 1},
                    const Eigen::Isometry3d& pose = Eigen::Isometry3d::Identity()) {
  MeshSpec spec;
  spec.type = MeshSpec::Type::kFile;
  spec.file.vertices = data.vertices;
  spec.file.triangles = data.triangles;
  spec.file.scale = scale;
  spec.T_world_mesh = pose;
  return BuildMesh(spec, 0);
}

// The generator (scenes/meshes/make_meshes.py) writes exact dimensions; floats hold them to 1e-6.
constexpr double kTol = 1e-5;

TEST(MeshFile, EachFormatLoadsClosedWithItsDimensions) {
  const auto pipe = LoadMeshFile(test::SourcePath("scenes/meshes/pipe.stl"));
  const Box p = Bounds(pipe.vertices);
  EXPECT_NEAR(p.lo.y(), -3.0, kTol);
  EXPECT_NEAR(p.hi.y(), 3.0, kTol);
  EXPECT_NEAR(p.hi.x(), 0.15, kTol);  // a vertex at angle 0 sits at the full radius
  EXPECT_EQ(pipe.triangles.size(), 4u * 32u);

  // COLLADA in centimetres, z up: metres after loading, and not turned to y up.
  const auto crate = LoadMeshFile(test::SourcePath("scenes/meshes/crate.dae"));
  const Box c = Bounds(crate.vertices);
  EXPECT_NEAR(c.lo.x(), -0.3, kTol);
  EXPECT_NEAR(c.hi.y(), 0.2, kTol);
  EXPECT_NEAR(c.lo.z(), 0.0, kTol);
  EXPECT_NEAR(c.hi.z(), 0.4, kTol);

  const auto quay = LoadMeshFile(test::SourcePath("scenes/meshes/quay_wall.ply"));
  const Box q = Bounds(quay.vertices);
  EXPECT_NEAR(q.hi.z(), 4.0, kTol);
  EXPECT_NEAR(q.hi.y() - q.lo.y(), 20.0, kTol);
  EXPECT_NEAR(q.hi.x(), 1.5, kTol);

  const auto rock = LoadMeshFile(test::SourcePath("scenes/meshes/rock.obj"));
  EXPECT_EQ(rock.triangles.size(), 20u * 16u);  // an icosphere subdivided twice

  for (const auto* data : {&pipe, &crate, &quay, &rock}) {
    TriangleMesh mesh = AsMesh(*data);
    const MeshCheck check = CheckMesh(mesh, "mesh");
    EXPECT_EQ(check.boundary_edges, 0u);
    EXPECT_EQ(check.non_manifold_edges, 0u);
    EXPECT_EQ(check.zero_area_triangles, 0u);
  }
}

TEST(MeshFile, ScaleThenPoseAreApplied) {
  const auto crate = LoadMeshFile(test::SourcePath("scenes/meshes/crate.dae"));
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(1, 2, 3);
  pose.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const TriangleMesh mesh = AsMesh(crate, {2, 1, 1}, pose);
  std::vector<Eigen::Vector3d> v;
  for (const auto& f : mesh.vertices) v.push_back(f.cast<double>());
  const Box b = Bounds(v);
  // x scaled to ±0.6 m, then turned onto y; y's ±0.2 m turned onto x.
  EXPECT_NEAR(b.lo.y(), 2 - 0.6, kTol);
  EXPECT_NEAR(b.hi.y(), 2 + 0.6, kTol);
  EXPECT_NEAR(b.hi.x(), 1 + 0.2, kTol);
  EXPECT_NEAR(b.hi.z(), 3 + 0.4, kTol);
}

TEST(MeshPreflight, OpenTankHasItsFourTopEdgesOpen) {
  MeshSpec spec;
  spec.type = MeshSpec::Type::kTank;
  spec.size_m = {4, 4, 1.5};
  TriangleMesh tank = BuildMesh(spec, 0);
  const MeshCheck check = CheckMesh(tank, "tank");
  // Each wall's quad is split by a diagonal, so its top rim is one edge: four rims in all.
  EXPECT_EQ(check.boundary_edges, 4u);
  EXPECT_EQ(check.non_manifold_edges, 0u);
}

TEST(MeshPreflight, RefusesNonFiniteVerticesAndDropsZeroAreaTriangles) {
  test::TempDir dir;
  const auto nan_obj = dir.path() / "nan.obj";
  std::ofstream(nan_obj) << "v 0 0 0\nv 1 0 0\nv 0 nan 0\nf 1 2 3\n";
  const std::string nan_error = test::InputErrorOf([&] {
    TriangleMesh mesh = AsMesh(LoadMeshFile(nan_obj.string()));
    (void)CheckMesh(mesh, nan_obj.string());
  });
  EXPECT_NE(nan_error.find(nan_obj.string() + ": vertex 2 is not finite"), std::string::npos)
      << nan_error;

  TriangleMesh mesh;
  mesh.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {2, 0, 0}};
  mesh.triangles = {{0, 1, 2}, {0, 1, 3}};  // the second is a line: zero area
  const MeshCheck check = CheckMesh(mesh, "m");
  EXPECT_EQ(check.zero_area_triangles, 1u);
  EXPECT_EQ(mesh.triangles.size(), 1u);
  EXPECT_EQ(check.boundary_edges, 3u);

  TriangleMesh only_degenerate;
  only_degenerate.vertices = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  only_degenerate.triangles = {{0, 1, 2}};
  EXPECT_NE(test::InputErrorOf([&] {
              (void)CheckMesh(only_degenerate, "flat");
            }).find("flat: no triangle with a non-zero area"),
            std::string::npos);
}

// A mesh file's triangles are counted from its text before Assimp builds them: past the budget it
// is refused with the count, in each format; within it, it loads.
TEST(MeshFile, TrianglesPastTheBudgetAreRefusedBeforeTheMeshIsBuilt) {
  test::TempDir dir;
  std::string obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n";
  for (int i = 0; i < 100; ++i) obj += "f 1 2 4 3\n";  // quads: two triangles each
  const std::string quads = test::WriteFile(dir, "quads.obj", obj);
  EXPECT_TRUE(test::ThrowsInputErrorWith(
      [&] { (void)LoadMeshFile(quads, 199); },
      {"quads.obj: holds 200 triangles, more than the 199", "--max-triangles"}));
  EXPECT_EQ(LoadMeshFile(quads, 200).triangles.size(), 200u);
  for (const auto& [file, triangles] :
       std::vector<std::pair<std::string, std::size_t>>{{"scenes/meshes/pipe.stl", 0},
                                                        {"scenes/meshes/crate.dae", 0},
                                                        {"scenes/meshes/quay_wall.ply", 0},
                                                        {"scenes/meshes/rock.obj", 0}}) {
    const std::string path = test::SourcePath(file);
    const std::size_t built = LoadMeshFile(path).triangles.size();
    EXPECT_TRUE(test::ThrowsInputErrorWith(
        [&] { (void)LoadMeshFile(path, static_cast<double>(built) - 1); },
        {"triangles, more than"}))
        << file << " (" << built << " triangles)";
    EXPECT_EQ(LoadMeshFile(path, static_cast<double>(built)).triangles.size(), built) << file;
  }
}

// A FIFO, a folder or a device where a mesh file goes is refused by its type, not called missing.
TEST(MeshFile, SpecialFilesAreRefusedByTheirType) {
  test::TempDir dir;
  const auto fifo = dir.path() / "rock.obj";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_TRUE(test::ThrowsInputErrorWith([&] { (void)LoadMeshFile(fifo.string()); },
                                         {"rock.obj: is a FIFO (expected a regular file)"}));
  EXPECT_TRUE(test::ThrowsInputErrorWith([&] { (void)LoadMeshFile(dir.path().string()); },
                                         {"is a directory"}));
  EXPECT_TRUE(test::ThrowsInputErrorWith([] { (void)LoadMeshFile("/dev/zero"); },
                                         {"is a character device"}));
}

TEST(MeshFile, MissingOrUnreadableFilesNameTheFile) {
  test::TempDir dir;
  EXPECT_NE(test::InputErrorOf([] {
              (void)LoadMeshFile("/nonexistent/rock.obj");
            }).find("/nonexistent/rock.obj: no such mesh file"),
            std::string::npos);
  const auto garbage = dir.path() / "garbage.stl";
  std::ofstream(garbage) << "this is not a mesh\n";
  const std::string error = test::InputErrorOf([&] { (void)LoadMeshFile(garbage.string()); });
  EXPECT_NE(error.find(garbage.string() + ": "), std::string::npos) << error;
}

// The shipped PLY file's text.
std::string QuayWallPly() {
  return ReadFileBytes(test::SourcePath("scenes/meshes/quay_wall.ply"), kMaxMeshFileBytes);
}

// Assimp 5.2 loops for ever on a PLY header without end_header, aborts on a body shorter than the
// header's counts, on a face of no vertices or on a form feed inside a number (it ends a line
// there), and segfaults on a vertex index past the vertices (each found by cutting or changing
// the shipped file). Each is now an input error naming the line or element. The shipped file's
// header is 10 lines: vertex 0 is on line 11, face 0 on line 21 and face 15 on line 36.
TEST(MeshFile, PlyFilesAssimpCannotReadAreClearErrors) {
  test::TempDir dir;
  const std::string ply = QuayWallPly();
  const std::size_t body = ply.find("end_header\n") + 11;
  // The shipped file with the first `from` after the header replaced by `to`.
  const auto changed = [&](const std::string& from, const std::string& to) {
    std::string text = ply;
    const std::size_t at = text.find(from, body);
    EXPECT_NE(at, std::string::npos) << from;
    return text.replace(at, from.size(), to);
  };
  for (const auto& [text, expected] : std::vector<std::pair<std::string, std::string>>{
           {ply.substr(0, body - 5), "the header has no 'end_header' line"},
           {ply.substr(0, ply.rfind("3 5 8 9\n")),
            "the body ends in element 'face' 15 of the 16 its header declares"},
           {ply.substr(0, ply.size() - 6),
            "line 36 holds fewer values than element 'face' 15 has properties"},
           {changed("\n3 0 1 6\n", "\n3 0 1\n6\n"),
            "line 21 holds fewer values than element 'face' 0 has properties"},
           {changed("\n3 0 1 6\n", "\n3 0 1 6 7\n"),
            "line 21 holds more values than element 'face' 0 has properties"},
           {changed("1.5000", "1\f.5000"), "line 12 holds the control character '\\x0c'"},
           {std::string(ply).replace(ply.find("vertex 10"), 6, std::string("vert\0x", 6)),
            "header line 4 holds the control character '\\x00'"},
           {changed("1.5000", "1,5000"), "line 12 holds '1,5000' where a number belongs"},
           {changed("\n3 0 1 6\n", "\n3 0 1 99\n"),
            "element 'face' 0: vertex index 99, expected a whole index from 0 of the 10 vertices"},
           {changed("\n3 0 1 6\n", "\n0\n"), "element 'face' 0: a face of no vertices"}}) {
    const std::string path = test::WriteFile(dir, "bad.ply", text);
    EXPECT_EQ(test::InputErrorOf([&] { (void)LoadMeshFile(path); }),
              path + ": not a readable PLY file: " + expected);
  }
  // Blank lines and CRLF line ends are read as the shipped file.
  std::string crlf;
  for (const char c : ply.substr(body)) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  const std::string loose =
      test::WriteFile(dir, "loose.ply", ply.substr(0, body) + "\n" + crlf + "\n");
  EXPECT_EQ(LoadMeshFile(loose).triangles,
            LoadMeshFile(test::SourcePath("scenes/meshes/quay_wall.ply")).triangles);
}

// Assimp reads a file as PLY by its extension or by content that begins "ply", so the check reads
// every such file first: a first line "ply\x12" once went past it, and Assimp leaked on the body.
TEST(MeshFile, EveryFileAssimpWouldReadAsPlyIsCheckedFirst) {
  test::TempDir dir;
  const std::string ply = QuayWallPly();
  const std::string odd_first_line = "ply\x12" + ply.substr(3);
  for (const std::string name : {"bad.ply", "bad.obj", "BAD.PLY"}) {
    const std::string path = test::WriteFile(dir, name, odd_first_line);
    EXPECT_EQ(
        test::InputErrorOf([&] { (void)LoadMeshFile(path); }),
        path + ": not a readable PLY file: header line 1 holds the control character '\\x12'");
  }
  const std::string stl = test::WriteFile(dir, "stl.ply", "solid x\nendsolid x\n");
  EXPECT_EQ(test::InputErrorOf([&] { (void)LoadMeshFile(stl); }),
            stl + ": not a readable PLY file: header line 1: expected 'ply', got 'solid x'");
}

// The check reads binary PLY of either byte order as the ASCII: the same file in each loads the
// same triangles, and is refused when one byte short.
TEST(MeshFile, BinaryPlyOfEitherOrderLoadsAsTheAscii) {
  test::TempDir dir;
  const std::string ascii = QuayWallPly();
  const MeshFileData expected = LoadMeshFile(test::WriteFile(dir, "ascii.ply", ascii));
  const std::size_t body = ascii.find("end_header\n") + 11;
  std::istringstream numbers(ascii.substr(body));
  std::vector<float> xyz(30);
  for (float& v : xyz) numbers >> v;
  std::vector<std::int32_t> faces;
  for (int f = 0, n = 0; f < 16 && numbers >> n; ++f) {
    faces.resize(faces.size() + 3);
    numbers >> faces[faces.size() - 3] >> faces[faces.size() - 2] >> faces.back();
  }
  ASSERT_EQ(faces.size(), 48u);
  for (const bool little : {true, false}) {
    SCOPED_TRACE(little ? "little-endian" : "big-endian");
    std::string text = ascii.substr(0, body);
    text.replace(text.find("format ascii"), 12,
                 little ? "format binary_little_endian" : "format binary_big_endian");
    const auto put = [&](const void* value, std::size_t bytes) {
      const auto* b = static_cast<const char*>(value);
      for (std::size_t i = 0; i < bytes; ++i) text += b[little ? i : bytes - 1 - i];
    };
    for (const float v : xyz) put(&v, sizeof v);
    for (std::size_t f = 0; f < faces.size(); f += 3) {
      text += '\x03';
      for (std::size_t k = f; k < f + 3; ++k) put(&faces[k], sizeof faces[k]);
    }
    const MeshFileData read = LoadMeshFile(test::WriteFile(dir, "binary.ply", text));
    EXPECT_EQ(read.triangles, expected.triangles);
    ASSERT_EQ(read.vertices.size(), expected.vertices.size());
    for (std::size_t v = 0; v < read.vertices.size(); ++v) {
      EXPECT_EQ(read.vertices[v], expected.vertices[v]);
    }
    const std::string cut = test::WriteFile(dir, "cut.ply", text.substr(0, text.size() - 1));
    EXPECT_NE(test::InputErrorOf([&] {
                (void)LoadMeshFile(cut);
              }).find("the body ends in element 'face' 15 of the 16"),
              std::string::npos);
  }
}

// Assimp 5.2 loops for ever on a COLLADA index list holding anything but whole numbers (found by
// changing digits of the shipped crate), reads "-1" as some index and takes 4e9 for a valid one;
// it segfaults on an array without a count (found by flipping a byte of the attribute's name) and
// reads only `count` items of a longer one. Each is now an input error naming the file's line.
// Every <instance_*> names an element of the file, and one visual scene is instantiated: Assimp
// leaked the scene it had built when <instance_visual_scene> named none or came twice, or an
// <instance_geometry> had no url.
TEST(MeshFile, ColladaInstancesMustNameAnElementOfTheFile) {
  test::TempDir dir;
  const std::string dae =
      ReadFileBytes(test::SourcePath("scenes/meshes/crate.dae"), kMaxMeshFileBytes);
  for (const auto& [from, to, expected] : std::vector<std::array<std::string, 3>>{
           {"url=\"#Scene\"", "url=\"#Nope\"",
            ":32: not a readable COLLADA file: <instance_visual_scene> refers to '#Nope'"},
           {"url=\"#Scene\"", "urxl=\"#Scene\"",
            ":32: not a readable COLLADA file: <instance_visual_scene> has no url"},
           {"<instance_geometry url=\"#crate-mesh\"/>", "<instance_geometry/>",
            ":29: not a readable COLLADA file: <instance_geometry> has no url"},
           {"url=\"#crate-mesh\"", "url=\"crate-mesh\"",
            ":29: not a readable COLLADA file: <instance_geometry> refers to 'crate-mesh'"}}) {
    std::string text = dae;
    const std::size_t at = text.find(from);
    ASSERT_NE(at, std::string::npos) << from;
    const std::string path = test::WriteFile(dir, "bad.dae", text.replace(at, from.size(), to));
    EXPECT_EQ(test::InputErrorOf([&] { (void)LoadMeshFile(path); }),
              path + expected + ", expected url=\"#ID\" naming an element of this file");
  }
  // Assimp aborts on a primitive of a nonzero count without its index list.
  std::string no_list = dae;
  const std::size_t list = no_list.find("<p>");
  ASSERT_NE(list, std::string::npos);
  no_list.erase(list, no_list.find("</p>") + 4 - list);
  const std::string no_list_path = test::WriteFile(dir, "no-list.dae", no_list);
  EXPECT_EQ(test::InputErrorOf([&] { (void)LoadMeshFile(no_list_path); }),
            no_list_path +
                ":20: not a readable COLLADA file: <triangles> of count 12 has no index list "
                "<p>, expected one");
  const std::string scene = "<instance_visual_scene url=\"#Scene\"/>";
  std::string twice = dae;
  twice.insert(twice.find(scene), scene);
  const std::string path = test::WriteFile(dir, "twice.dae", twice);
  EXPECT_EQ(test::InputErrorOf([&] { (void)LoadMeshFile(path); }),
            path +
                ":32: not a readable COLLADA file: a second <instance_visual_scene>, expected "
                "one (COLLADA's <scene> holds one)");
}

TEST(MeshFile, ColladaFilesAssimpCannotReadAreClearErrors) {
  test::TempDir dir;
  const std::string dae =
      ReadFileBytes(test::SourcePath("scenes/meshes/crate.dae"), kMaxMeshFileBytes);
  const std::size_t list = dae.find("<p>0 2 3 ");
  ASSERT_NE(list, std::string::npos);
  for (const std::string item : {"x", "1.5", "-1", "4000000000"}) {
    std::string text = dae;
    text.replace(list, 6, "<p>0 " + item);
    const std::string path = test::WriteFile(dir, "bad.dae", text);
    EXPECT_EQ(test::InputErrorOf([&] { (void)LoadMeshFile(path); }),
              path + ":22: not a readable COLLADA file: <p> holds '" + item +
                  "' where an index (a whole number from 0 to 2^31 - 1) belongs");
  }
  const std::string count = "count=\"24\">-30 -20 0";
  const std::size_t array = dae.find(count);
  ASSERT_NE(array, std::string::npos);
  for (const std::string said : {"xount=\"24\"", "count=\"10\"", "count=\"x\""}) {
    std::string text = dae;
    text.replace(array, 10, said);
    const std::string path = test::WriteFile(dir, "bad.dae", text);
    EXPECT_EQ(test::InputErrorOf([&] { (void)LoadMeshFile(path); }),
              path + ":12: not a readable COLLADA file: <float_array> holds 24 items, expected " +
                  "its count attribute to say so, as count=\"24\"");
  }
  // What XML and COLLADA allow loads as the shipped file does.
  const auto triangles = LoadMeshFile(test::SourcePath("scenes/meshes/crate.dae")).triangles;
  std::string plus = dae;
  plus.replace(list, 6, "<p>0 +2");
  EXPECT_EQ(LoadMeshFile(test::WriteFile(dir, "plus.dae", plus)).triangles, triangles);
  std::string quoted = dae;
  quoted.replace(array, 10, "count = '+024'");
  EXPECT_EQ(LoadMeshFile(test::WriteFile(dir, "quoted.dae", quoted)).triangles, triangles);
}

}  // namespace
}  // namespace sonarbench::sim
