// Append-only log of finished build tasks (ours).
#include "BuildJournal.h"

#include "ChunkStorage.h"

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <stdexcept>
#include <sys/stat.h>
#include <unistd.h>

namespace resmr
{
namespace
{
constexpr uint32_t RecordMagic = 0x4c4e524aU; // "JRNL"
constexpr std::size_t RecordHead = 12;        // magic, size, CRC
} // namespace

BuildJournal::BuildJournal(const std::string& path, std::vector<std::vector<uint8_t>>& records)
  : Path(path)
{
  this->Descriptor = open(path.c_str(), O_RDWR | O_CREAT, 0644);
  if (this->Descriptor < 0)
  {
    throw std::runtime_error(path + ": cannot open the build journal: " + std::strerror(errno));
  }
  struct stat info;
  const uint64_t size = fstat(this->Descriptor, &info) == 0 ? static_cast<uint64_t>(info.st_size) : 0;
  records.clear();
  uint64_t at = 0;
  while (at + RecordHead <= size)
  {
    uint32_t head[3];
    if (pread(this->Descriptor, head, sizeof(head), static_cast<off_t>(at)) != static_cast<ssize_t>(sizeof(head)) ||
      head[0] != RecordMagic || at + RecordHead + head[1] > size)
    {
      break;
    }
    std::vector<uint8_t> record(head[1]);
    if ((head[1] > 0 &&
          pread(this->Descriptor, record.data(), head[1], static_cast<off_t>(at + RecordHead)) !=
            static_cast<ssize_t>(head[1])) ||
      Crc32(record.data(), record.size()) != head[2])
    {
      break;
    }
    records.push_back(std::move(record));
    at += RecordHead + head[1];
  }
  if (at != size && ftruncate(this->Descriptor, static_cast<off_t>(at)) != 0)
  {
    const std::string reason = std::strerror(errno);
    close(this->Descriptor);
    throw std::runtime_error(path + ": cannot cut the build journal's torn end: " + reason);
  }
  this->Size = at;
}

BuildJournal::~BuildJournal()
{
  if (this->Descriptor >= 0)
  {
    close(this->Descriptor);
  }
}

void BuildJournal::Append(const std::vector<uint8_t>& record)
{
  std::vector<uint8_t> bytes(RecordHead + record.size());
  const uint32_t head[3] = { RecordMagic, static_cast<uint32_t>(record.size()), Crc32(record.data(), record.size()) };
  std::memcpy(bytes.data(), head, sizeof(head));
  if (!record.empty())
  {
    std::memcpy(bytes.data() + RecordHead, record.data(), record.size());
  }
  std::size_t done = 0;
  while (done < bytes.size())
  {
    const ssize_t written =
      pwrite(this->Descriptor, bytes.data() + done, bytes.size() - done, static_cast<off_t>(this->Size + done));
    if (written <= 0)
    {
      const std::string reason = std::strerror(errno);
      // Cut the torn record now, so that later appends follow whole ones (the next open cuts it
      // anyway if this fails too).
      const int cut = ftruncate(this->Descriptor, static_cast<off_t>(this->Size));
      static_cast<void>(cut);
      throw std::runtime_error(this->Path + ": build journal write failed (disk full?): " + reason);
    }
    done += static_cast<std::size_t>(written);
  }
  if (fdatasync(this->Descriptor) != 0)
  {
    throw std::runtime_error(this->Path + ": build journal sync failed: " + std::strerror(errno));
  }
  this->Size += bytes.size();
}

} // namespace resmr
