// Toolbar "Reservoir Inspect", action "Inspect Cells": while it is on, resting the cursor on a
// Multiresolution Surface in the active render view shows the original cell under it in a
// tooltip (I, J, K, active, depth, the values of the property file at the current time, the
// colour array first), and a click selects it: it is outlined in the view ('Selected Cell', its
// corners from the finest level) and its information stays in the Multiresolution Readout dock.
// The camera keeps its mouse (a drag still rotates). The pick is the representation's PickAt,
// made where the surface renders (pvserver included).
#ifndef pqMultiresolutionInspectActions_h
#define pqMultiresolutionInspectActions_h

#include <QActionGroup>
#include <QPoint>
#include <QPointer>
#include <QString>
#include <QTimer>

#include <vector>

class pqRenderView;
class pqView;
class vtkObject;
class vtkSMProxy;

class pqMultiresolutionInspectActions : public QActionGroup
{
  Q_OBJECT
  typedef QActionGroup Superclass;

public:
  pqMultiresolutionInspectActions(QObject* parent);
  ~pqMultiresolutionInspectActions() override;

  /// The text the last click selected (empty: none), for the readout dock.
  static QString SelectedText();
  /// The last pick or inspection of `surface` as text (empty: nothing picked), and the cell's
  /// corners (24 values, world; empty when unknown).
  static QString Describe(vtkSMProxy* surface, std::vector<double>& corners);
  /// Selects: `text` becomes SelectedText, and `corners` (if any) are outlined in `view`.
  static void Select(pqRenderView* view, const QString& text, const std::vector<double>& corners);
  /// Picks at display pixel `at` of `view` (from its lower left) in the frame on screen, and
  /// selects the cell when `select`; the cell's text, empty over no cell.
  static QString Pick(pqRenderView* view, const QPoint& at, bool select);

private Q_SLOTS:
  void setOn(bool on);
  void setView(pqView* view);
  void pickHovered();

private:
  Q_DISABLE_COPY(pqMultiresolutionInspectActions)
  void Observe(bool on);
  void OnMouse(vtkObject* caller, unsigned long event, void*);

  QAction* Inspect;
  QPointer<pqRenderView> View;
  QTimer Hover;
  QPoint At, Pressed;
  bool ButtonDown = false;
  unsigned long Observers[3] = { 0, 0, 0 };
};

#endif
