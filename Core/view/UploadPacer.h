// Bounding the time a frame spends copying newly loaded meshes to the GPU, paper Sec. 6.1 and
// 6.3: the loader prepares meshes off the render thread, but the copy into GPU buffers happens
// on it, and its cost per byte is not steady: a buffer whose storage is fresh (the driver
// allocates and zeroes it, the kernel faults its pages in) costs tens of times more a byte
// than memory the process already touched (bench/results/view.md). A byte cap alone cannot
// tell the two apart, so the pacer predicts each copy's time from what the last copies cost.
//
// Contract:
// - BeginFrame(budgetMs, byteCap) starts a frame's account; Spend(bytes, ms) charges work
//   already done in it (the model's tables) without teaching the estimate.
// - Admit(bytes) says whether a mesh of that size may still be copied this frame: always when
//   no mesh has been copied yet (every frame makes progress, however large the mesh, whatever
//   the tables took), else only while the bytes stay within the cap and the predicted time
//   within the budget. Only copies teach the estimate, so a frame whose tables took the
//   budget must still copy: after one slow copy (a fresh allocation, 33 ms a MB once) the
//   estimate kept every mesh out for as long as a large model's tables streamed (12 s on
//   the 300M-cell model) and the picture stayed at its stand-ins.
// - Record(bytes, ms) charges a copy and teaches the estimate (milliseconds per MB): it rises
//   at once to a slower sample and decays slowly towards faster ones, so one cheap copy after
//   reused memory does not admit a burst of fresh allocations. Copies under 64 KB, timed
//   mostly by call overhead, are charged but do not teach it.
#pragma once

#include <cstddef>

namespace resmr
{

class UploadPacer
{
public:
  /// The estimate before any copy was timed: between the two cases above, nearer the slow one.
  static constexpr double InitialMsPerMB = 2.0;
  static constexpr std::size_t SmallestTimedBytes = std::size_t(64) << 10;

  void BeginFrame(double budgetMs, std::size_t byteCap);
  void Spend(std::size_t bytes, double ms);
  bool Admit(std::size_t bytes) const;
  void Record(std::size_t bytes, double ms);

  double MsPerMB() const { return this->Estimate; }
  double SpentMs() const { return this->FrameMs; }
  std::size_t SpentBytes() const { return this->FrameBytes; }

private:
  double Estimate = InitialMsPerMB;
  double BudgetMs = 0;
  std::size_t ByteCap = 0;
  double FrameMs = 0;
  std::size_t FrameBytes = 0;
  std::size_t CopiedBytes = 0; ///< this frame's meshes (Record), not its tables (Spend)
};

} // namespace resmr
