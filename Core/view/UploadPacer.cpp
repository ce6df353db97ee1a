// Pacing the render thread's GPU uploads by predicted time, paper Sec. 6.1 and 6.3.
#include "UploadPacer.h"

#include <algorithm>
#include <cmath>

namespace resmr
{

void UploadPacer::BeginFrame(double budgetMs, std::size_t byteCap)
{
  this->BudgetMs = std::max(0.0, budgetMs);
  this->ByteCap = byteCap;
  this->FrameMs = 0;
  this->FrameBytes = 0;
  this->CopiedBytes = 0;
}

void UploadPacer::Spend(std::size_t bytes, double ms)
{
  this->FrameBytes += bytes;
  this->FrameMs += std::isfinite(ms) ? std::max(0.0, ms) : 0.0;
}

bool UploadPacer::Admit(std::size_t bytes) const
{
  if (this->CopiedBytes == 0)
  {
    return true;
  }
  const double predictedMs = this->Estimate * static_cast<double>(bytes) / (1 << 20);
  return this->FrameBytes + bytes <= this->ByteCap && this->FrameMs + predictedMs <= this->BudgetMs;
}

void UploadPacer::Record(std::size_t bytes, double ms)
{
  this->Spend(bytes, ms);
  this->CopiedBytes += bytes;
  if (bytes < SmallestTimedBytes || !std::isfinite(ms) || ms < 0)
  {
    return;
  }
  const double sample = ms / (static_cast<double>(bytes) / (1 << 20));
  this->Estimate = sample > this->Estimate ? sample : 0.9 * this->Estimate + 0.1 * sample;
}

} // namespace resmr
