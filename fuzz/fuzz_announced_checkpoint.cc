// Fuzz target: checkpoint announcements as the evaluator handles them
// (evaluator/announced_checkpoint.h): the announced path resolved and checked against the run's
// checkpoint folder, the file opened without following a link or blocking and read up to the
// size bound, then parsed (nn::ParseCheckpoint) and its network built with its parameters, as
// the evaluator builds it. The run folder (in $TMPDIR) holds, besides the input's file
// checkpoints/ckpt.bin, the traps a key holder could name: a FIFO (checkpoints/fifo.bin), links to
// /dev/zero and to a checkpoint outside the folder, a link to the folder's parent, and that
// outside checkpoint; relative paths are taken from the run folder.
// Input: one byte L, then L bytes of the announced path, then the file's bytes. The file is
// loaded as given and again with its size field and CRC-32 made right (as fuzz_checkpoint).
// Contract checked: a path or file is refused by std::runtime_error only; nothing blocks (the
// run's timeout), reads without end or crashes; only files in the folder are ever parsed.
#include <sys/stat.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>
#include <string>

#include "evaluator/announced_checkpoint.h"
#include "fuzz/fuzz_support.h"
#include "nn/checkpoint.h"
#include "nn/sequential.h"

namespace {

namespace fs = std::filesystem;

// Makes the run folder with its traps; returns checkpoints/ckpt.bin's path (resolved).
std::string SetUp() {
  const char* tmp = std::getenv("TMPDIR");
  std::string pattern = std::string(tmp != nullptr ? tmp : "/tmp") + "/fuzz-announced-XXXXXX";
  if (::mkdtemp(pattern.data()) == nullptr) {
    std::perror("mkdtemp");
    std::abort();
  }
  const fs::path run = pattern;
  fs::create_directories(run / "checkpoints");
  std::mt19937 rng(1);
  const rl::nn::Sequential net = rl::nn::MakeMlp(4, {8}, 2, &rng);
  rl::nn::Checkpoint outside;
  outside.architecture = net.Architecture();
  net.GetFlat(&outside.params);
  rl::nn::SaveCheckpoint((run / "outside.bin").string(), outside);
  if (::mkfifo((run / "checkpoints/fifo.bin").c_str(), 0600) != 0) std::abort();
  fs::create_symlink("/dev/zero", run / "checkpoints/zero.bin");
  fs::create_symlink(run / "outside.bin", run / "checkpoints/outside.bin");
  fs::create_directory_symlink(run, run / "checkpoints/up");
  std::string file = fs::canonical(run / "checkpoints").string() + "/ckpt.bin";
  // Removed at exit; a crash leaves it for the reproducer's inspection.
  static const fs::path removed = run;
  std::atexit([] {
    std::error_code ec;
    fs::remove_all(removed, ec);
  });
  return file;
}

void Write(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  if (!out) std::abort();
}

// The run folder (of checkpoints/ckpt.bin): relative paths are taken from there, as the
// evaluator started in it would take them.
std::string RunFolder(const std::string& file) {
  return fs::path(file).parent_path().parent_path();
}

void Read(const std::string& path, const std::string& file) {
  const std::string run = RunFolder(file);
  const std::string announced = !path.empty() && path[0] != '/' ? run + "/" + path : path;
  try {
    const rl::nn::Checkpoint ckpt =
        rl::evaluator::ReadAnnouncedCheckpoint(announced, run + "/checkpoints");
    // The one regular file of the folder is the only one that can have been read.
    std::error_code ec;
    if (fs::canonical(announced, ec) != fs::path(file)) {
      std::fprintf(stderr, "fuzz_announced_checkpoint: read '%s', not %s\n", announced.c_str(),
                   file.c_str());
      std::abort();
    }
    rl::fuzz::BuildNetwork(ckpt);
  } catch (const std::runtime_error&) {
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string file = SetUp();
  if (size == 0) return 0;
  const size_t path_size = std::min<size_t>(data[0], size - 1);
  const std::string announced(reinterpret_cast<const char*>(data) + 1, path_size);
  std::string bytes(reinterpret_cast<const char*>(data) + 1 + path_size, size - 1 - path_size);
  Write(file, bytes);
  Read(announced, file);
  if (rl::fuzz::FixCheckpointSizeAndCrc(&bytes)) {
    Write(file, bytes);
    Read(announced, file);
  }
  return 0;
}
