#include <gtest/gtest.h>
#include <sys/file.h>
#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/io/output_directory.hpp"
#include "test_util.hpp"

namespace sonarbench::io {
namespace {

namespace fs = std::filesystem;

std::string Bytes(const fs::path& path) { return ReadFileBytes(path.string(), kMaxJsonBytes); }

void Put(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream(path, std::ios::binary) << text;
}

OutputClaim Claim(OutputMode mode, std::string config = "a") {
  OutputClaim claim;
  claim.command = "test";
  claim.config_sha256 = std::move(config);
  claim.mode = mode;
  claim.files = {"report.json", "map.bt", "sub/item.json"};
  claim.record = "report.json";
  return claim;
}

// Writes each claimed file as `text` under the directory's write root.
void WriteAll(const OutputDirectory& out, const OutputClaim& claim, const std::string& text) {
  for (const std::string& file : claim.files) Put(out.write_root() / file, text);
}

TEST(OutputDirectory, FilesOfTheUsersNamesAreRefusedAndLeftAsTheyWere) {
  test::TempDir dir;
  Put(dir.path() / "map.bt", "the user's map");
  Put(dir.path() / "notes.txt", "notes");
  const std::string error = test::InputErrorOf(
      [&] { const OutputDirectory out(dir.path().string(), Claim(OutputMode::kReplace)); });
  EXPECT_NE(error.find("holds files sonarbench did not write: map.bt"), std::string::npos) << error;
  EXPECT_EQ(Bytes(dir.path() / "map.bt"), "the user's map");
  // A file where an output's folder goes is named as well.
  fs::remove(dir.path() / "map.bt");
  Put(dir.path() / "sub", "the user's file");
  EXPECT_NE(test::InputErrorOf([&] {
              const OutputDirectory out(dir.path().string(), Claim(OutputMode::kReplace));
            }).find("did not write: sub (where a folder goes)"),
            std::string::npos);
  EXPECT_EQ(Bytes(dir.path() / "sub"), "the user's file");
  // The refused open leaves no lock or marker behind.
  EXPECT_FALSE(fs::exists(dir.path() / OutputDirectory::kLockFile));
  EXPECT_FALSE(fs::exists(dir.path() / OutputDirectory::kMarkerFile));
}

TEST(OutputDirectory, AForeignMarkerIsNotOwnership) {
  test::TempDir dir;
  Put(dir.path() / OutputDirectory::kMarkerFile, R"({"files": ["map.bt"]})");
  Put(dir.path() / "map.bt", "the user's map");
  EXPECT_NE(test::InputErrorOf([&] {
              const OutputDirectory out(dir.path().string(), Claim(OutputMode::kReplace));
            }).find("did not write"),
            std::string::npos);
  // A marker of ours that lists paths outside the directory does not own them.
  Put(dir.path() / "outside.txt", "keep");
  fs::remove(dir.path() / "map.bt");
  const fs::path inner = dir.path() / "out";
  Put(inner / OutputDirectory::kMarkerFile,
      R"({"tool": "sonarbench",
          "outputs": {"test": {"config_sha256": "b", "files": ["../outside.txt", "/etc/x"]}}})");
  Put(inner / "report.json", "old");
  OutputClaim claim = Claim(OutputMode::kResume);
  claim.force = true;
  EXPECT_NE(test::InputErrorOf([&] {
              const OutputDirectory out(inner.string(), claim);
            }).find("did not write: report.json"),
            std::string::npos);
  EXPECT_EQ(Bytes(dir.path() / "outside.txt"), "keep");
  const auto owned = OwnedFiles(inner);
  ASSERT_TRUE(owned);
  EXPECT_EQ(std::count(owned->begin(), owned->end(), "../outside.txt"), 0);
}

TEST(OutputDirectory, AnUncommittedRunLeavesTheEarlierOutputsWhole) {
  test::TempDir dir;
  const OutputClaim claim = Claim(OutputMode::kReplace);
  {
    OutputDirectory out(dir.path().string(), claim);
    WriteAll(out, claim, "first");
    out.Commit();
  }
  {
    // Killed or failed half way: the staged files go, the committed ones stay.
    const OutputDirectory out(dir.path().string(), claim);
    Put(out.write_root() / "map.bt", "second");
  }
  for (const std::string& file : claim.files) EXPECT_EQ(Bytes(dir.path() / file), "first");
  EXPECT_FALSE(fs::exists(dir.path() / OutputDirectory::kStageDir));
}

// Writes what a writer of `claim` killed while staging leaves: the marker listing its files, its
// name in the lock file, staged files and a staged temporary file.
void LeaveAKilledRun(const fs::path& dir, const OutputClaim& claim) {
  { const OutputDirectory out(dir.string(), claim); }
  const fs::path stage = dir / OutputDirectory::kStageDir;
  Put(stage / "report.json", "staged");
  Put(stage / "map.bt.tmp.4242", "half of a map");
  Put(stage / "sub" / "item.json.tmp.17", "half of an item");
  Put(dir / OutputDirectory::kLockFile,
      "sonarbench test, pid 4242 on host, config a\n"
      "sonarbench test, pid 17 on host, config a\n");
}

// A run killed while writing a staged file leaves "NAME.tmp.PID" and staged files in the stage
// (the release that removes them never ran); the next run removes them and commits.
TEST(OutputDirectory, AKilledRunsStagedTemporaryIsRemovedByTheNext) {
  test::TempDir dir;
  const OutputClaim claim = Claim(OutputMode::kReplace);
  const fs::path stage = dir.path() / OutputDirectory::kStageDir;
  LeaveAKilledRun(dir.path(), claim);
  OutputDirectory out(dir.path().string(), claim);
  EXPECT_FALSE(fs::exists(stage / "map.bt.tmp.4242"));
  EXPECT_FALSE(fs::exists(stage / "sub" / "item.json.tmp.17"));
  EXPECT_FALSE(fs::exists(stage / "report.json"));
  WriteAll(out, claim, "second");
  out.Commit();
  for (const std::string& file : claim.files) EXPECT_EQ(Bytes(dir.path() / file), "second");
  EXPECT_FALSE(fs::exists(stage));
}

// Another command (of another claim) finds a killed run's stage: it clears it too, and commits.
TEST(OutputDirectory, AKilledRunsStageDoesNotStopAnotherCommand) {
  test::TempDir dir;
  LeaveAKilledRun(dir.path(), Claim(OutputMode::kReplace));
  OutputClaim other = Claim(OutputMode::kReplace);
  other.command = "other";
  other.files = {"other.json"};
  other.record = "other.json";
  OutputDirectory out(dir.path().string(), other);
  Put(out.write_root() / "other.json", "other");
  out.Commit();
  EXPECT_EQ(Bytes(dir.path() / "other.json"), "other");
  EXPECT_FALSE(fs::exists(dir.path() / OutputDirectory::kStageDir));
}

// A file in the stage no marker lists, or a stage in a directory sonarbench did not write, is
// the user's: refused by name, left as it was.
TEST(OutputDirectory, AStagingFolderOfTheUsersIsRefused) {
  test::TempDir dir;
  const fs::path stage = dir.path() / OutputDirectory::kStageDir;
  Put(stage / "notes.txt", "the user's");
  EXPECT_NE(test::InputErrorOf([&] {
              const OutputDirectory out(dir.path().string(), Claim(OutputMode::kReplace));
            }).find("did not write: .sonarbench-stage"),
            std::string::npos);
  {
    OutputDirectory out(dir.path().string() + "/b", Claim(OutputMode::kReplace));
    WriteAll(out, Claim(OutputMode::kReplace), "first");
    out.Commit();
  }
  Put(dir.path() / "b" / OutputDirectory::kStageDir / "notes.txt", "the user's");
  EXPECT_NE(test::InputErrorOf([&] {
              const OutputDirectory out((dir.path() / "b").string(), Claim(OutputMode::kReplace));
            }).find("did not write: .sonarbench-stage/notes.txt"),
            std::string::npos);
  EXPECT_EQ(Bytes(stage / "notes.txt"), "the user's");
  EXPECT_EQ(Bytes(dir.path() / "b" / OutputDirectory::kStageDir / "notes.txt"), "the user's");
}

TEST(OutputDirectory, ACommitLeavesNoFileOfTheEarlierRun) {
  test::TempDir dir;
  const OutputClaim claim = Claim(OutputMode::kReplace);
  {
    OutputDirectory out(dir.path().string(), claim);
    WriteAll(out, claim, "first");
    out.Commit();
  }
  OutputDirectory out(dir.path().string(), claim);
  Put(out.write_root() / "report.json", "second");
  out.Commit();
  EXPECT_EQ(Bytes(dir.path() / "report.json"), "second");
  EXPECT_FALSE(fs::exists(dir.path() / "map.bt"));
  EXPECT_FALSE(fs::exists(dir.path() / "sub"));
}

TEST(OutputDirectory, ASymlinkIsFollowedNotReplaced) {
  test::TempDir dir;
  fs::create_directories(dir.path() / "real");
  fs::create_symlink(dir.path() / "real", dir.path() / "link");
  const OutputClaim claim = Claim(OutputMode::kReplace);
  OutputDirectory out((dir.path() / "link").string(), claim);
  WriteAll(out, claim, "x");
  out.Commit();
  EXPECT_TRUE(fs::is_symlink(dir.path() / "link"));
  EXPECT_EQ(Bytes(dir.path() / "real/map.bt"), "x");
}

TEST(OutputDirectory, InputsAreNeverOutputs) {
  test::TempDir dir;
  OutputClaim claim = Claim(OutputMode::kReplace);
  {
    OutputDirectory out(dir.path().string(), claim);
    WriteAll(out, claim, "first");
    out.Commit();
  }
  claim.inputs = {(dir.path() / "sub/../map.bt").string()};
  const std::string error =
      test::InputErrorOf([&] { const OutputDirectory out(dir.path().string(), claim); });
  EXPECT_NE(error.find("never overwrites or removes its inputs"), std::string::npos) << error;
  EXPECT_EQ(Bytes(dir.path() / "map.bt"), "first");
}

TEST(OutputDirectory, ForceRemovesOnlyListedFilesNeverATree) {
  test::TempDir dir;
  OutputClaim claim = Claim(OutputMode::kResume, "a");
  {
    const OutputDirectory out(dir.path().string(), claim);
    WriteAll(out, claim, "a");
  }
  Put(dir.path() / "sub/mine.txt", "the user's");
  Put(dir.path() / "map.bt.tmp.123", "a half-written temporary file");
  Put(dir.path() / OutputDirectory::kLockFile, "sonarbench test, pid 123 on host, config a\n");
  Put(dir.path() / "thesis.tmp.1", "the user's too");
  Put(dir.path() / "report.json.tmp.99", "the user's, named as a temporary file");
  claim.config_sha256 = "b";
  EXPECT_NE(test::InputErrorOf([&] {
              const OutputDirectory out(dir.path().string(), claim);
            }).find("another configuration (config_sha256 a); pass --force"),
            std::string::npos);
  EXPECT_EQ(Bytes(dir.path() / "map.bt"), "a");
  claim.force = true;
  claim.files = {"report.json"};
  { const OutputDirectory out(dir.path().string(), claim); }
  EXPECT_FALSE(fs::exists(dir.path() / "map.bt"));
  EXPECT_FALSE(fs::exists(dir.path() / "sub/item.json"));
  EXPECT_FALSE(fs::exists(dir.path() / "map.bt.tmp.123"));
  EXPECT_EQ(Bytes(dir.path() / "sub/mine.txt"), "the user's");
  EXPECT_EQ(Bytes(dir.path() / "thesis.tmp.1"), "the user's too");
  EXPECT_EQ(Bytes(dir.path() / "report.json.tmp.99"), "the user's, named as a temporary file");
  // The marker now lists only what this claim may write.
  EXPECT_EQ(*OwnedFiles(dir.path()),
            (std::vector<std::string>{OutputDirectory::kMarkerFile, OutputDirectory::kLockFile,
                                      "report.json"}));
}

TEST(OutputDirectory, ForceRemovesOnlyTheSameCommandsFiles) {
  test::TempDir dir;
  OutputClaim dataset = Claim(OutputMode::kResume, "a");
  dataset.command = "simulate";
  { WriteAll(OutputDirectory(dir.path().string(), dataset), dataset, "dataset"); }
  OutputClaim study = Claim(OutputMode::kResume, "b");
  study.command = "sweep";
  study.files = {"study.json"};
  study.record = "study.json";
  { WriteAll(OutputDirectory(dir.path().string(), study), study, "study"); }
  study.config_sha256 = "c";
  study.force = true;
  { const OutputDirectory out(dir.path().string(), study); }
  EXPECT_FALSE(fs::exists(dir.path() / "study.json"));
  for (const std::string& file : dataset.files) EXPECT_EQ(Bytes(dir.path() / file), "dataset");
  const auto owned = ReadOwnership(dir.path());
  ASSERT_TRUE(owned);
  EXPECT_EQ(owned->at("simulate").files.size(), dataset.files.size());
  EXPECT_EQ(owned->at("sweep").config_sha256, "c");
}

// A resume continues only the same command's files: another command's in the way are refused,
// and --force replaces that command's output whole (none of it left beside the new one).
TEST(OutputDirectory, AResumeNeverContinuesAnotherCommandsFiles) {
  test::TempDir dir;
  OutputClaim simulated = Claim(OutputMode::kResume, "a");
  simulated.command = "simulate";
  simulated.files.push_back("truth/occupancy.bt");
  { WriteAll(OutputDirectory(dir.path().string(), simulated), simulated, "simulated"); }
  OutputClaim imported = Claim(OutputMode::kResume, "b");
  imported.command = "import";
  const std::string error =
      test::InputErrorOf([&] { const OutputDirectory out(dir.path().string(), imported); });
  EXPECT_NE(error.find("holds sonarbench simulate outputs that import would write (map.bt"),
            std::string::npos)
      << error;
  for (const std::string& file : simulated.files) EXPECT_EQ(Bytes(dir.path() / file), "simulated");
  imported.force = true;
  { const OutputDirectory out(dir.path().string(), imported); }
  for (const std::string& file : simulated.files) EXPECT_FALSE(fs::exists(dir.path() / file));
  const auto owned = ReadOwnership(dir.path());
  ASSERT_TRUE(owned);
  EXPECT_FALSE(owned->contains("simulate"));
  EXPECT_EQ(owned->at("import").config_sha256, "b");
}

// A folder where sonarbench writes a file (an edited marker that lists one) is refused before
// --force removes anything.
TEST(OutputDirectory, AFolderAnEditedMarkerListsIsRefusedBeforeAnythingIsRemoved) {
  test::TempDir dir;
  OutputClaim claim = Claim(OutputMode::kResume, "a");
  { WriteAll(OutputDirectory(dir.path().string(), claim), claim, "a"); }
  const fs::path marker = dir.path() / OutputDirectory::kMarkerFile;
  auto edited = nlohmann::json::parse(Bytes(marker));
  edited["outputs"]["test"]["files"].push_back("sub");
  Put(marker, edited.dump());
  claim.force = true;
  claim.config_sha256 = "b";
  const std::string error =
      test::InputErrorOf([&] { const OutputDirectory out(dir.path().string(), claim); });
  EXPECT_NE(error.find("sub, where sonarbench writes a file, is a folder"), std::string::npos)
      << error;
  for (const std::string& file : claim.files) EXPECT_EQ(Bytes(dir.path() / file), "a");
}

// A lock file that is a symlink (dangling or not) or a hard link is refused: the file it names is
// never truncated or made.
TEST(OutputDirectory, ALinkedLockFileIsRefusedAndNeverWritten) {
  test::TempDir dir;
  const fs::path precious = dir.path() / "precious.txt";
  Put(precious, "precious");
  const fs::path out = dir.path() / "out";
  fs::create_directories(out);
  const fs::path lock = out / OutputDirectory::kLockFile;
  for (const char* kind : {"symlink", "hard link", "dangling"}) {
    fs::remove(lock);
    if (std::string(kind) == "hard link") {
      fs::create_hard_link(precious, lock);
    } else {
      fs::create_symlink(std::string(kind) == "dangling" ? dir.path() / "made.txt" : precious,
                         lock);
    }
    const std::string error = test::InputErrorOf(
        [&] { const OutputDirectory o(out.string(), Claim(OutputMode::kReplace)); });
    EXPECT_NE(error.find(std::string(kind) == "hard link" ? "hard link" : "is a symlink"),
              std::string::npos)
        << kind << ": " << error;
    EXPECT_EQ(Bytes(precious), "precious") << kind;
    EXPECT_FALSE(fs::exists(dir.path() / "made.txt")) << kind;
    EXPECT_FALSE(fs::exists(out / OutputDirectory::kMarkerFile)) << kind;
  }
}

TEST(OutputDirectory, TheFileSystemsRootIsRefused) {
  EXPECT_NE(test::InputErrorOf([] {
              const OutputDirectory out("/", Claim(OutputMode::kResume));
            }).find("is the file system's root"),
            std::string::npos);
}

// A run that fails after staging keeps the last complete result: DiscardStaged empties the stage
// and HoldsRecord tells that result is there.
TEST(OutputDirectory, AFailedRunCanLeaveTheLastResultWhole) {
  test::TempDir dir;
  const OutputClaim claim = Claim(OutputMode::kReplace);
  {
    OutputDirectory out(dir.path().string(), claim);
    EXPECT_FALSE(out.HoldsRecord());
    WriteAll(out, claim, "first");
    out.Commit();
  }
  OutputDirectory out(dir.path().string(), claim);
  Put(out.write_root() / "map.bt", "half of the second");
  out.DiscardStaged();
  EXPECT_FALSE(fs::exists(out.write_root() / "map.bt"));
  EXPECT_TRUE(out.HoldsRecord());
  for (const std::string& file : claim.files) EXPECT_EQ(Bytes(dir.path() / file), "first");
}

TEST(OutputDirectory, NothingIsWrittenOrRemovedThroughASymlinkedFolder) {
  test::TempDir dir;
  OutputClaim claim = Claim(OutputMode::kResume, "a");
  {
    const OutputDirectory out((dir.path() / "out").string(), claim);
    WriteAll(out, claim, "ours");
  }
  // The user swaps the folder for a link to their own files of the same names.
  Put(dir.path() / "mine/item.json", "theirs");
  fs::remove_all(dir.path() / "out/sub");
  fs::create_directory_symlink(dir.path() / "mine", dir.path() / "out/sub");
  claim.force = true;
  const std::string error =
      test::InputErrorOf([&] { const OutputDirectory out((dir.path() / "out").string(), claim); });
  EXPECT_NE(error.find("/sub is a symlink"), std::string::npos) << error;
  EXPECT_EQ(Bytes(dir.path() / "mine/item.json"), "theirs");
}

TEST(OutputDirectory, OneConfigurationWritesAtATime) {
  test::TempDir dir;
  const OutputClaim mine = Claim(OutputMode::kResume, "a");
  const OutputDirectory first(dir.path().string(), mine);
  // A shard of the same configuration joins; another configuration is refused, naming the
  // holder, and so is --force while a writer works.
  { const OutputDirectory shard(dir.path().string(), mine); }
  const std::string error = test::InputErrorOf(
      [&] { const OutputDirectory other(dir.path().string(), Claim(OutputMode::kResume, "b")); });
  EXPECT_NE(error.find("another sonarbench is writing here ('sonarbench test, pid " +
                       std::to_string(::getpid())),
            std::string::npos)
      << error;
  OutputClaim forced = mine;
  forced.force = true;
  EXPECT_NE(test::InputErrorOf([&] {
              const OutputDirectory f(dir.path().string(), forced);
            }).find("--force never removes a running writer's files"),
            std::string::npos);
  EXPECT_NE(test::InputErrorOf([&] {
              const OutputDirectory one_shot(dir.path().string(), Claim(OutputMode::kReplace));
            }).find("another sonarbench is writing here"),
            std::string::npos);
}

TEST(OutputDirectory, ADirectoryMadeForNothingGoesAgain) {
  test::TempDir dir;
  const fs::path made = dir.path() / "a/b";
  { const OutputDirectory out(made.string(), Claim(OutputMode::kReplace)); }
  EXPECT_FALSE(fs::exists(made));
  // One whose outputs were committed stays, with an empty lock file.
  {
    const OutputClaim claim = Claim(OutputMode::kReplace);
    OutputDirectory out(made.string(), claim);
    WriteAll(out, claim, "x");
    out.Commit();
  }
  EXPECT_EQ(Bytes(made / "report.json"), "x");
  EXPECT_EQ(Bytes(made / OutputDirectory::kLockFile), "");
}

TEST(OutputDirectory, ADatasetWrittenBeforeMarkersIsOwnedThroughItsManifest) {
  test::TempDir dir;
  Put(dir.path() / "beams/sweep_0000.bin", "beams");
  Put(dir.path() / "manifest.json",
      R"({"format": "sonarbench-dataset", "config_sha256": "a",
          "files": [{"path": "beams/sweep_0000.bin"}]})");
  EXPECT_EQ(*OwnedFiles(dir.path()),
            (std::vector<std::string>{"beams/sweep_0000.bin", "manifest.json"}));
  Put(dir.path() / "manifest.json", R"({"format": "webapp", "files": [{"path": "x"}]})");
  EXPECT_FALSE(OwnedFiles(dir.path()));
}

TEST(OutputDirectory, AReportWrittenBeforeMarkersOwnsTheOutputsItNames) {
  test::TempDir dir;
  Put(dir.path() / "report.json",
      R"({"tool": {"name": "sonarbench"}, "outputs": {"map": "map.bt", "bad": "../x"}})");
  EXPECT_EQ(*OwnedFiles(dir.path()), (std::vector<std::string>{"map.bt", "report.json"}));
  const OutputClaim claim = Claim(OutputMode::kReplace);
  OutputDirectory out(dir.path().string(), claim);
  WriteAll(out, claim, "new");
  out.Commit();
  EXPECT_EQ(Bytes(dir.path() / "map.bt"), "new");
  Put(dir.path() / "other/report.json", R"({"tool": {"name": "webapp"}, "outputs": {}})");
  EXPECT_FALSE(OwnedFiles(dir.path() / "other"));
}

}  // namespace
}  // namespace sonarbench::io
