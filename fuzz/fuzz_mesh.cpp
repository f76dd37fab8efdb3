// A mesh file as a scene's `file:` names it: the first byte picks the format (PLY, COLLADA, OBJ,
// STL), the rest is the file. The PLY and COLLADA guards run first, then Assimp.
#include <array>

#include "fuzz_support.hpp"
#include "sonarbench/sim/world/mesh_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sonarbench;
  if (size == 0) return 0;
  static const std::array<const char*, 4> kExtensions = {".ply", ".dae", ".obj", ".stl"};
  const auto path = fuzz::ScratchDir() / (std::string("mesh") + kExtensions[data[0] % 4]);
  fuzz::WriteBytes(path, fuzz::AsText(data + 1, size - 1));
  return fuzz::KeepsTheContract([&] { (void)sim::LoadMeshFile(path.string(), 1e5); });
}
