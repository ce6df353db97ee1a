#include "DiskUse.h"

#include <chrono>
#include <dirent.h>
#include <sys/stat.h>
#include <sys/statvfs.h>

namespace resmr
{
namespace
{
/// `path`, or its nearest parent folder that exists.
std::string Existing(std::string path)
{
  struct stat info;
  while (!path.empty() && stat(path.c_str(), &info) != 0)
  {
    const std::size_t slash = path.find_last_of('/');
    path = slash == std::string::npos ? std::string(".") : slash == 0 ? std::string("/") : path.substr(0, slash);
  }
  return path.empty() ? std::string(".") : path;
}

template<typename Visit>
void ForEachFile(const std::string& folder, const Visit& visit)
{
  DIR* directory = opendir(folder.c_str());
  if (!directory)
  {
    return;
  }
  while (const dirent* entry = readdir(directory))
  {
    const std::string name = entry->d_name;
    if (name == "." || name == "..")
    {
      continue;
    }
    struct stat info;
    const std::string path = folder + "/" + name;
    if (lstat(path.c_str(), &info) != 0)
    {
      continue; // removed meanwhile
    }
    if (S_ISDIR(info.st_mode))
    {
      ForEachFile(path, visit);
    }
    else if (S_ISREG(info.st_mode))
    {
      visit(name, info);
    }
  }
  closedir(directory);
}
} // namespace

uint64_t FolderBytes(const std::string& folder)
{
  uint64_t bytes = 0;
  // Allocated blocks, not the apparent size: what the disk really gives up.
  ForEachFile(folder, [&](const std::string&, const struct stat& info) { bytes += uint64_t(info.st_blocks) * 512; });
  return bytes;
}

uint64_t SiblingBytes(const std::string& path, const std::string& suffix)
{
  const std::size_t slash = path.find_last_of('/');
  const std::string folder = slash == std::string::npos ? "." : path.substr(0, slash);
  const std::string prefix = (slash == std::string::npos ? path : path.substr(slash + 1)) + suffix;
  uint64_t bytes = 0;
  DIR* directory = opendir(folder.c_str());
  if (!directory)
  {
    return 0;
  }
  while (const dirent* entry = readdir(directory))
  {
    struct stat info;
    const std::string name = entry->d_name;
    if (name.compare(0, prefix.size(), prefix) == 0 && lstat((folder + "/" + name).c_str(), &info) == 0 &&
      S_ISREG(info.st_mode))
    {
      bytes += uint64_t(info.st_blocks) * 512;
    }
  }
  closedir(directory);
  return bytes;
}

uint64_t FreeDiskBytes(const std::string& path)
{
  struct statvfs info;
  if (statvfs(Existing(path).c_str(), &info) != 0)
  {
    return UINT64_MAX; // unknown: do not refuse
  }
  return uint64_t(info.f_bavail) * info.f_frsize;
}

bool SameFilesystem(const std::string& a, const std::string& b)
{
  struct stat first, second;
  return stat(Existing(a).c_str(), &first) == 0 && stat(Existing(b).c_str(), &second) == 0 &&
    first.st_dev == second.st_dev;
}

DiskMeter::DiskMeter(const std::string& scratch, const std::string& output, int periodMs)
  : Scratch(scratch)
  , Output(output)
{
  this->Thread = std::thread([this, periodMs] {
    std::unique_lock<std::mutex> lock(this->Lock);
    while (!this->Stop)
    {
      lock.unlock();
      this->Sample();
      lock.lock();
      this->Wake.wait_for(lock, std::chrono::milliseconds(periodMs), [this] { return this->Stop; });
    }
  });
}

DiskMeter::~DiskMeter()
{
  {
    std::lock_guard<std::mutex> guard(this->Lock);
    this->Stop = true;
  }
  this->Wake.notify_all();
  this->Thread.join();
}

void DiskMeter::Sample(uint64_t extraBytes)
{
  const uint64_t scratch = FolderBytes(this->Scratch);
  const uint64_t total = scratch + SiblingBytes(this->Output, ".partial-") + extraBytes;
  uint64_t peak = this->PeakScratch.load();
  while (scratch > peak && !this->PeakScratch.compare_exchange_weak(peak, scratch))
  {
  }
  peak = this->PeakTotal.load();
  while (total > peak && !this->PeakTotal.compare_exchange_weak(peak, total))
  {
  }
}

} // namespace resmr
