// Dock window "Multiresolution Readout" (issue 7, point 4): the live readout of the
// Multiresolution Surface in the active view (the active source's, else the first visible
// one), refreshed after each render of that view.
#ifndef pqMultiresolutionReadoutDock_h
#define pqMultiresolutionReadoutDock_h

#include <QDockWidget>
#include <QPointer>
#include <QTimer>

class QLabel;
class QDoubleSpinBox;
class QSpinBox;
class pqView;

class pqMultiresolutionReadoutDock : public QDockWidget
{
  Q_OBJECT
  typedef QDockWidget Superclass;

public:
  pqMultiresolutionReadoutDock(QWidget* parent = nullptr);
  ~pqMultiresolutionReadoutDock() override;

private Q_SLOTS:
  void setView(pqView* view);
  void updateReadout();
  /// The camera to the cell of the I, J, K boxes, which is selected (outlined, kept here).
  void goToCell();
  /// The camera's focal point to the map point and depth of the X, Y, Depth boxes (its
  /// direction and distance kept); the cell then shown at the view's centre is selected.
  void goToPoint();

private:
  Q_DISABLE_COPY(pqMultiresolutionReadoutDock)
  QPointer<pqView> View;
  QTimer Update; ///< coalesces the signals that ask for an update into one pull
  QLabel* Source;
  QLabel* Tolerance;
  QLabel* Estimated;
  QLabel* Resident;
  QLabel* Triangles;
  QLabel* Regions;
  QLabel* Frame;
  QLabel* Loads;
  QLabel* Error;
  QLabel* Selected;         ///< the cell the Inspect Cells action last selected
  QSpinBox* Cell[3];        ///< I, J, K for goToCell
  QDoubleSpinBox* Point[3]; ///< x, y, depth for goToPoint
  QWidget* Values;
};

#endif
