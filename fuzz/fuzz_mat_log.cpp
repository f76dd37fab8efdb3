// A MATLAB .mat log of the real sonar (v5, or v7.3 HDF5 when libmatio has it), with the layout
// check that ReadMatLog applies to its variables, under a limit of 64 MiB (file and inflated).
#include "fuzz_support.hpp"
#include "sonarbench/io/mat_log.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sonarbench;
  const auto path = fuzz::ScratchDir() / "log.mat";
  fuzz::WriteBytes(path, fuzz::AsText(data, size));
  return fuzz::KeepsTheContract(
      [&] { (void)io::ReadMatLog(path.string(), std::uint64_t{64} << 20); });
}
