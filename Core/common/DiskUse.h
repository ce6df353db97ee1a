// Disk a hierarchy build takes: the bytes of its scratch folder, sampled while it runs, and the
// free space of the filesystems it writes to. Ours: the paper builds on a machine with 256 GB
// of memory (Sec. 7) and says nothing of disk; on a workstation the disk is the bound, so a
// build states what it needs before it starts and reports what it took.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <string>
#include <thread>

namespace resmr
{

/// Bytes of the regular files under `folder`, recursively (0 if it does not exist).
uint64_t FolderBytes(const std::string& folder);

/// Bytes of the regular files in the folder of `path` whose names start with the name of
/// `path` followed by `suffix` (an output being written under a temporary name).
uint64_t SiblingBytes(const std::string& path, const std::string& suffix);

/// Free bytes an unprivileged writer may use on the filesystem holding `path`, or its
/// nearest existing parent folder.
uint64_t FreeDiskBytes(const std::string& path);

/// True if the two paths (or their nearest existing parents) lie on one filesystem.
bool SameFilesystem(const std::string& a, const std::string& b);

/// Samples a build's disk on a thread of its own, every `periodMs`, from construction to
/// destruction: the scratch folder alone, and with the output's temporary file.
class DiskMeter
{
public:
  DiskMeter(const std::string& scratch, const std::string& output, int periodMs = 200);
  ~DiskMeter();
  DiskMeter(const DiskMeter&) = delete;
  DiskMeter& operator=(const DiskMeter&) = delete;

  /// Samples now (so the peak holds the present too), with `extraBytes` written elsewhere
  /// counted in the total.
  void Sample(uint64_t extraBytes = 0);
  uint64_t PeakScratchBytes() const { return this->PeakScratch; }
  uint64_t PeakTotalBytes() const { return this->PeakTotal; }

private:
  std::string Scratch, Output;
  std::atomic<uint64_t> PeakScratch{ 0 }, PeakTotal{ 0 };
  std::mutex Lock;
  std::condition_variable Wake;
  bool Stop = false;
  std::thread Thread;
};

} // namespace resmr
