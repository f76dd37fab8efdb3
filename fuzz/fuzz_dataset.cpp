// A sonarbench dataset folder as `sonarbench map` reads it. The input is the folder's three files
// one after the other, each section after a marker line:
//   manifest.json, then "\n@@beams/sweep_0000.bin\n" (or sweep_0001), then "\n@@poses/sonar.tum\n";
// a section left out leaves its file out, one under another name is dropped.
#include <algorithm>
#include <array>
#include <string>

#include "fuzz_support.hpp"
#include "sonarbench/io/dataset.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sonarbench;
  namespace fs = std::filesystem;
  static const std::array<std::string_view, 4> kFiles = {"manifest.json", "beams/sweep_0000.bin",
                                                         "beams/sweep_0001.bin", "poses/sonar.tum"};
  const fs::path dir = fuzz::ScratchDir() / "dataset";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::string_view rest = fuzz::AsText(data, size);
  std::string_view name = kFiles[0];
  while (true) {
    const std::size_t marker = rest.find("\n@@");
    const std::size_t end = marker == std::string_view::npos ? rest.size() : marker;
    if (std::find(kFiles.begin(), kFiles.end(), name) != kFiles.end())
      fuzz::WriteBytes(dir / name, rest.substr(0, end));
    if (marker == std::string_view::npos) break;
    rest.remove_prefix(marker + 3);
    const std::size_t eol = std::min(rest.find('\n'), rest.size());
    name = rest.substr(0, eol);
    rest.remove_prefix(std::min(eol + 1, rest.size()));
  }
  return fuzz::KeepsTheContract([&] { (void)io::ReadDataset(dir.string()); });
}
