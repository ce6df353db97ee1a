#include "pqMultiresolutionRefreshManager.h"

#include "pqMultiresolutionReadout.h"

#include "pqApplicationCore.h"
#include "pqRenderView.h"
#include "pqRepresentation.h"
#include "pqServerManagerModel.h"
#include "pqView.h"
#include "vtkLogger.h"

#include <QPointer>
#include <QTimer>

#include <algorithm>

namespace
{
// Long enough to let the loader threads land a few meshes between frames, short enough that
// detail streams in visibly.
constexpr int RefreshDelayMs = 30;
// A frame lowering the tolerance by less than this counts as settled (the controller's
// smallest refining step is 2%).
constexpr double RefiningStep = 0.99;
}

struct pqMultiresolutionRefreshManager::ViewState
{
  QTimer Timer;
  bool OwnRender = false;                               ///< the render now ending is one this manager asked for
  std::map<vtkSMProxy*, pqMultiresolutionReadout> Last; ///< each surface's previous frame
};

pqMultiresolutionRefreshManager::pqMultiresolutionRefreshManager(QObject* parent)
  : Superclass(parent)
{
  pqServerManagerModel* model = pqApplicationCore::instance()->getServerManagerModel();
  QObject::connect(model, &pqServerManagerModel::preViewAdded, this, &pqMultiresolutionRefreshManager::onViewAdded);
  QObject::connect(model, &pqServerManagerModel::preViewRemoved, this, &pqMultiresolutionRefreshManager::onViewRemoved);
  for (pqView* view : model->findItems<pqView*>())
  {
    this->onViewAdded(view);
  }
}

pqMultiresolutionRefreshManager::~pqMultiresolutionRefreshManager() = default;

void pqMultiresolutionRefreshManager::onViewAdded(pqView* view)
{
  if (!qobject_cast<pqRenderView*>(view) || this->Views.count(view))
  {
    return;
  }
  auto state = std::make_unique<ViewState>();
  state->Timer.setSingleShot(true);
  ViewState* raw = state.get();
  QPointer<pqView> guarded(view);
  QObject::connect(&state->Timer, &QTimer::timeout, this, [raw, guarded]() {
    if (guarded)
    {
      vtkLogF(TRACE, "multiresolution refresh: rendering");
      raw->OwnRender = true;
      guarded->render();
    }
  });
  QObject::connect(view, &pqView::endRender, this, &pqMultiresolutionRefreshManager::onRenderEnded);
  this->Views[view] = std::move(state);
}

void pqMultiresolutionRefreshManager::onViewRemoved(pqView* view)
{
  QObject::disconnect(view, &pqView::endRender, this, &pqMultiresolutionRefreshManager::onRenderEnded);
  this->Views.erase(view);
}

void pqMultiresolutionRefreshManager::onRenderEnded()
{
  pqView* view = qobject_cast<pqView*>(this->sender());
  const auto found = this->Views.find(view);
  if (found == this->Views.end())
  {
    return;
  }
  ViewState& state = *found->second;
  const bool own = state.OwnRender;
  state.OwnRender = false;

  bool again = false;
  int delayMs = RefreshDelayMs;
  std::map<vtkSMProxy*, pqMultiresolutionReadout> last;
  for (pqRepresentation* representation : view->getRepresentations())
  {
    vtkSMProxy* surface = pqMultiresolutionReadout::Surface(representation, true);
    if (!surface)
    {
      continue;
    }
    const pqMultiresolutionReadout readout = pqMultiresolutionReadout::Pull(surface);
    const auto before = state.Last.find(surface);
    const pqMultiresolutionReadout* previous = before != state.Last.end() ? &before->second : nullptr;
    // Loads that finish while a frame draws leave nothing pending, but that frame stood in
    // ancestors for them: render again, as long as each such frame changes something (a load
    // that failed or does not fit the budget would give the same frame forever).
    const bool changed = !own || !previous || previous->Regions != readout.Regions ||
      previous->Triangles != readout.Triangles || previous->Substituted != readout.Substituted;
    // A moving frame drawn at a reduced resolution: the still frame after it is drawn in full.
    again = again || readout.LoadsPending || (readout.Substituted > 0 && changed) || readout.RenderScale < 1;
    if (readout.TargetFrameRate <= 0 && readout.LoadsPending)
    {
      // What the surface says (resmr::RefreshWaitMs, at most 1 s): the last frame's time while
      // its loaders read, so that slow frames leave them the machine.
      delayMs = std::max(delayMs, static_cast<int>(readout.RefreshWaitMs));
    }
    if (readout.TargetFrameRate > 0)
    {
      // The controller counts the gap between back-to-back frames as frame time: keep it
      // well inside the target so refreshing does not itself coarsen the view.
      delayMs = std::min(delayMs, std::max(1, static_cast<int>(250 / readout.TargetFrameRate)));
      const bool refining = previous && readout.Tolerance < RefiningStep * previous->Tolerance;
      again = again || !own || refining;
    }
    last[surface] = readout;
  }
  state.Last.swap(last);
  // A complete frame rendered from elsewhere meanwhile does not cancel a scheduled refresh:
  // that costs one frame at most, and a frame never goes unrefreshed for a race.
  if (again)
  {
    vtkLogF(TRACE, "multiresolution refresh: next render in %d ms", delayMs);
    state.Timer.start(delayMs);
  }
}
