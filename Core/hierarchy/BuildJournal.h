// The log that lets a one-process hierarchy build resume after a kill, a crash or a full disk
// (ours): one record a finished task, appended once the task's chunks and scratch files are
// written, so whatever the log holds is whole on disk.
//
// Contract:
// - A record is the caller's bytes with their size and CRC-32; Append() writes it and syncs
//   the file before returning (it is the commit point of the task).
// - Open() reads every whole record from the start and cuts off a torn or damaged tail (a
//   record whose writing stopped), so the log holds exactly the records it returns.
// - Write failures throw std::runtime_error naming the file.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace resmr
{

class BuildJournal
{
public:
  /// Opens (creating if missing) the log at `path` and gives its whole records in `records`.
  BuildJournal(const std::string& path, std::vector<std::vector<uint8_t>>& records);
  ~BuildJournal();
  BuildJournal(const BuildJournal&) = delete;
  BuildJournal& operator=(const BuildJournal&) = delete;

  void Append(const std::vector<uint8_t>& record);

private:
  std::string Path;
  int Descriptor = -1;
  uint64_t Size = 0;
};

} // namespace resmr
