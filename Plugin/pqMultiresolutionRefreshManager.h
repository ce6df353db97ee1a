// Progressive refresh of Multiresolution Surfaces in the GUI (issue 7, point 3).
//
// The surface never waits for the loader thread: a frame draws what is resident and asks for
// the rest. Without another render the finer meshes, once loaded, would only appear at the
// next mouse move. After each render of a render view, this asks its visible Multiresolution
// Surfaces for their readout (pulled from the render server) and schedules one more render of
// that view, a few tens of milliseconds later, while
// - meshes or property tables are still loading (LoadsPending), or the frame stood in
//   ancestors for regions not loaded yet (RegionsSubstituted) and differs from the last, or
// - a target frame rate is set and the frame-rate controller is still refining: after any
//   render that was not ours (the still frame after an interaction can afford more detail),
//   and then while each frame lowers the tolerance, or
// - the frame was drawn at a reduced resolution while the camera moved: the next render of
//   the same camera is the still frame, drawn in full.
// One single-shot timer per view: renders from anywhere restart it, so requests coalesce,
// and nothing is scheduled once nothing is loading and the tolerance holds.
#ifndef pqMultiresolutionRefreshManager_h
#define pqMultiresolutionRefreshManager_h

#include <QObject>

#include <map>
#include <memory>

class pqView;

class pqMultiresolutionRefreshManager : public QObject
{
  Q_OBJECT
  typedef QObject Superclass;

public:
  pqMultiresolutionRefreshManager(QObject* parent = nullptr);
  ~pqMultiresolutionRefreshManager() override;

  void onStartup() {}
  void onShutdown() {}

private Q_SLOTS:
  void onViewAdded(pqView* view);
  void onViewRemoved(pqView* view);
  void onRenderEnded();

private:
  Q_DISABLE_COPY(pqMultiresolutionRefreshManager)
  struct ViewState;
  std::map<pqView*, std::unique_ptr<ViewState>> Views;
};

#endif
