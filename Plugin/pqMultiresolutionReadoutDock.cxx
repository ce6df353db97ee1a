#include "pqMultiresolutionReadoutDock.h"

#include "pqMultiresolutionInspectActions.h"
#include "pqMultiresolutionReadout.h"

#include "pqActiveObjects.h"
#include "pqDataRepresentation.h"
#include "pqPipelineSource.h"
#include "pqRenderView.h"
#include "pqView.h"
#include "vtkLogger.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxy.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QLocale>
#include <QPushButton>
#include <QSpinBox>
#include <QVBoxLayout>

pqMultiresolutionReadoutDock::pqMultiresolutionReadoutDock(QWidget* parent)
  : Superclass(parent)
{
  this->setWindowTitle(tr("Multiresolution Readout"));
  auto* body = new QWidget(this);
  body->setObjectName("ReadoutBody"); // names for ParaView's test playback
  auto* layout = new QVBoxLayout(body);
  this->Source = new QLabel(body);
  this->Source->setWordWrap(true);
  layout->addWidget(this->Source);

  this->Values = new QWidget(body);
  auto* form = new QFormLayout(this->Values);
  form->setContentsMargins(0, 0, 0, 0);
  const auto row = [&](const QString& name, const QString& help) {
    auto* value = new QLabel(this->Values);
    value->setTextInteractionFlags(Qt::TextSelectableByMouse);
    value->setToolTip(help);
    form->addRow(name, value);
    return value;
  };
  this->Tolerance = row(tr("Tolerance"), tr("Projected error tolerance of the last frame, pixels"));
  this->Estimated = row(tr("Estimated error"),
    tr("The last frame's estimated error, pixels: the largest typical distance of a drawn region from the "
       "original grid, seen at its centre (the tolerance bounds the largest, seen at the nearest point)"));
  this->Resident = row(tr("Resident"), tr("Memory held by loaded meshes, of the memory budget"));
  this->Triangles = row(tr("Triangles drawn"), tr("Triangles drawn in the last frame"));
  this->Regions = row(tr("Regions drawn"),
    tr("Region meshes drawn in the last frame; in brackets, those standing in for finer ones still loading"));
  this->Frame = row(tr("Last frame"), tr("Time the last frame took"));
  this->Loads = row(tr("Loads"), tr("Whether meshes the view wants are still loading"));
  layout->addWidget(this->Values);

  this->Error = new QLabel(body);
  this->Error->setWordWrap(true);
  this->Error->setStyleSheet("color: #c0392b;");
  this->Error->setTextInteractionFlags(Qt::TextSelectableByMouse);
  layout->addWidget(this->Error);
  // Go to cell: ECLIPSE's I, J, K.
  auto* go = new QWidget(body);
  go->setObjectName("GoToCellRow");
  auto* goRow = new QHBoxLayout(go);
  goRow->setContentsMargins(0, 0, 0, 0);
  const char* names[3] = { "I", "J", "K" };
  for (int a = 0; a < 3; ++a)
  {
    goRow->addWidget(new QLabel(names[a], go));
    this->Cell[a] = new QSpinBox(go);
    this->Cell[a]->setRange(1, 1 << 30);
    this->Cell[a]->setObjectName(QString("GoTo%1").arg(names[a]));
    goRow->addWidget(this->Cell[a], 1);
  }
  auto* button = new QPushButton(tr("Go to cell"), go);
  button->setObjectName("GoToCell");
  button->setToolTip(tr("Fly the camera to cell I, J, K (ECLIPSE's, from 1) and select it"));
  QObject::connect(button, &QPushButton::clicked, this, &pqMultiresolutionReadoutDock::goToCell);
  goRow->addWidget(button);
  layout->addWidget(go);
  // Go to point: map x, y (the view's world coordinates) and depth (positive down).
  auto* goPoint = new QWidget(body);
  goPoint->setObjectName("GoToPointRow");
  auto* pointRow = new QHBoxLayout(goPoint);
  pointRow->setContentsMargins(0, 0, 0, 0);
  const char* axes[3] = { "X", "Y", "Depth" };
  for (int a = 0; a < 3; ++a)
  {
    pointRow->addWidget(new QLabel(axes[a], goPoint));
    this->Point[a] = new QDoubleSpinBox(goPoint);
    this->Point[a]->setRange(-1e12, 1e12);
    this->Point[a]->setDecimals(2);
    this->Point[a]->setObjectName(QString("GoTo%1").arg(axes[a]));
    pointRow->addWidget(this->Point[a], 1);
  }
  auto* pointButton = new QPushButton(tr("Go to point"), goPoint);
  pointButton->setObjectName("GoToPoint");
  pointButton->setToolTip(tr("Fly the camera to map point X, Y at Depth (positive down) and select the cell shown "
                             "there"));
  QObject::connect(pointButton, &QPushButton::clicked, this, &pqMultiresolutionReadoutDock::goToPoint);
  pointRow->addWidget(pointButton);
  layout->addWidget(goPoint);
  this->Selected = new QLabel(body);
  this->Selected->setWordWrap(true);
  this->Selected->setTextInteractionFlags(Qt::TextSelectableByMouse);
  this->Selected->setToolTip(tr("The cell last selected with Inspect Cells (toolbar Reservoir Inspect)"));
  layout->addWidget(this->Selected);
  layout->addStretch(1);
  this->setWidget(body);

  // Zero-delay single shot: runs once the render and the other handlers of its signal are
  // done, and once for any number of requests made meanwhile.
  this->Update.setSingleShot(true);
  this->Update.setInterval(0);
  QObject::connect(&this->Update, &QTimer::timeout, this, &pqMultiresolutionReadoutDock::updateReadout);
  const auto request = [this]() { this->Update.start(); };
  pqActiveObjects& active = pqActiveObjects::instance();
  QObject::connect(&active, &pqActiveObjects::viewChanged, this, &pqMultiresolutionReadoutDock::setView);
  QObject::connect(
    &active, QOverload<pqDataRepresentation*>::of(&pqActiveObjects::representationChanged), this, request);
  QObject::connect(this, &QDockWidget::visibilityChanged, this, request);
  this->setView(active.activeView());
}

pqMultiresolutionReadoutDock::~pqMultiresolutionReadoutDock() = default;

void pqMultiresolutionReadoutDock::setView(pqView* view)
{
  if (this->View)
  {
    QObject::disconnect(this->View, nullptr, this, nullptr);
  }
  this->View = view;
  if (view)
  {
    const auto request = [this]() { this->Update.start(); };
    QObject::connect(view, &pqView::endRender, this, request);
    QObject::connect(view, &pqView::representationVisibilityChanged, this, request);
  }
  this->Update.start();
}

void pqMultiresolutionReadoutDock::updateReadout()
{
  if (!this->isVisible())
  {
    return;
  }
  // The active source's surface, else the first one shown in the active view.
  pqRepresentation* chosen = nullptr;
  pqDataRepresentation* activeRepresentation = pqActiveObjects::instance().activeRepresentation();
  if (this->View && activeRepresentation && activeRepresentation->getView() == this->View &&
    pqMultiresolutionReadout::Surface(activeRepresentation, false))
  {
    chosen = activeRepresentation;
  }
  for (int i = 0; this->View && !chosen && i < this->View->getNumberOfRepresentations(); ++i)
  {
    pqRepresentation* representation = this->View->getRepresentation(i);
    if (pqMultiresolutionReadout::Surface(representation, true))
    {
      chosen = representation;
    }
  }
  vtkSMProxy* surface = pqMultiresolutionReadout::Surface(chosen, false);
  if (!surface)
  {
    this->Source->setText(tr("No Multiresolution Surface in the active view."));
    this->Values->setVisible(false);
    this->Selected->setVisible(false);
    this->Error->setVisible(false);
    return;
  }

  const pqMultiresolutionReadout readout = pqMultiresolutionReadout::Pull(surface);
  const QLocale locale(QLocale::English);
  auto* data = qobject_cast<pqDataRepresentation*>(chosen);
  pqPipelineSource* input = data ? data->getInput() : nullptr;
  this->Source->setText(input ? input->getSMName() : tr("Multiresolution Surface"));
  const QString holding = readout.TargetFrameRate <= 0 ? tr("fixed")
    : !readout.Moving                                  ? tr("still frame: the set tolerance")
    : readout.RenderScale < 1
    ? tr("holding %1 fps, drawn at %2% resolution").arg(readout.TargetFrameRate).arg(qRound(100 * readout.RenderScale))
    : tr("holding %1 fps").arg(readout.TargetFrameRate);
  this->Tolerance->setText(tr("%1 px (%2)").arg(readout.Tolerance, 0, 'f', 2).arg(holding));
  this->Estimated->setText(tr("%1 px").arg(readout.EstimatedError, 0, 'f', 2));
  this->Resident->setText(tr("%1 MB of %2 MB").arg(readout.ResidentMB, 0, 'f', 1).arg(readout.BudgetMB));
  this->Triangles->setText(locale.toString(static_cast<qlonglong>(readout.Triangles)));
  this->Regions->setText(tr("%1 (%2 standing in)").arg(readout.Regions).arg(readout.Substituted));
  this->Frame->setText(tr("%1 ms").arg(readout.FrameMs, 0, 'f', 1));
  this->Loads->setText(readout.LoadsPending ? tr("pending") : tr("idle"));
  this->Error->setText(readout.Error);
  const QString selected = pqMultiresolutionInspectActions::SelectedText();
  this->Selected->setText(selected.isEmpty() ? QString() : tr("Selected: %1").arg(selected));
  this->Selected->setVisible(!selected.isEmpty());
  this->Values->setVisible(true);
  this->Error->setVisible(!readout.Error.isEmpty());
  vtkLogF(TRACE, "multiresolution readout: %.2f px, %.1f MB, %.0f triangles, %d regions, %d substituted, %s",
    readout.Tolerance, readout.ResidentMB, readout.Triangles, readout.Regions, readout.Substituted,
    readout.LoadsPending ? "pending" : "idle");
}

void pqMultiresolutionReadoutDock::goToCell()
{
  auto* view = qobject_cast<pqRenderView*>(this->View.data());
  vtkSMProxy* surface = nullptr;
  for (int i = 0; view && !surface && i < view->getNumberOfRepresentations(); ++i)
  {
    surface = pqMultiresolutionReadout::Surface(view->getRepresentation(i), true);
  }
  if (!surface)
  {
    return;
  }
  // Described at once from the files (InspectCell), where the surface renders.
  vtkSMPropertyHelper(surface, "InspectCell").Set(0, this->Cell[0]->value());
  vtkSMPropertyHelper(surface, "InspectCell").Set(1, this->Cell[1]->value());
  vtkSMPropertyHelper(surface, "InspectCell").Set(2, this->Cell[2]->value());
  surface->UpdateVTKObjects();
  surface->UpdatePropertyInformation();
  const int zero[3] = { 0, 0, 0 };
  vtkSMPropertyHelper(surface, "InspectCell").Set(zero, 3);
  surface->UpdateVTKObjects();
  std::vector<double> corners;
  const QString text = pqMultiresolutionInspectActions::Describe(surface, corners);
  if (corners.size() == 24 && std::isfinite(corners[0]))
  {
    // The cell's centre becomes the focal point, seen from the camera's direction at 25 times
    // the cell's size.
    double centre[3] = { 0, 0, 0 }, low[3], high[3];
    for (int a = 0; a < 3; ++a)
    {
      low[a] = high[a] = corners[a];
      for (int c = 0; c < 8; ++c)
      {
        centre[a] += corners[3 * c + a] / 8;
        low[a] = std::min(low[a], corners[3 * c + a]);
        high[a] = std::max(high[a], corners[3 * c + a]);
      }
    }
    const double size = std::max({ high[0] - low[0], high[1] - low[1], high[2] - low[2] });
    vtkSMProxy* camera = view->getProxy();
    double position[3], focal[3];
    vtkSMPropertyHelper(camera, "CameraPosition").Get(position, 3);
    vtkSMPropertyHelper(camera, "CameraFocalPoint").Get(focal, 3);
    const double along[3] = { position[0] - focal[0], position[1] - focal[1], position[2] - focal[2] };
    const double length = std::sqrt(along[0] * along[0] + along[1] * along[1] + along[2] * along[2]);
    for (int a = 0; a < 3; ++a)
    {
      position[a] = centre[a] + (length > 0 ? along[a] / length : (a == 2 ? 1.0 : 0.0)) * 25 * size;
    }
    vtkSMPropertyHelper(camera, "CameraFocalPoint").Set(centre, 3);
    vtkSMPropertyHelper(camera, "CameraPosition").Set(position, 3);
    vtkSMPropertyHelper(camera, "CenterOfRotation").Set(centre, 3);
    camera->UpdateVTKObjects();
  }
  pqMultiresolutionInspectActions::Select(view, text, corners);
  this->Update.start();
}

void pqMultiresolutionReadoutDock::goToPoint()
{
  auto* view = qobject_cast<pqRenderView*>(this->View.data());
  if (!view)
  {
    return;
  }
  vtkSMProxy* camera = view->getProxy();
  double position[3], focal[3];
  vtkSMPropertyHelper(camera, "CameraPosition").Get(position, 3);
  vtkSMPropertyHelper(camera, "CameraFocalPoint").Get(focal, 3);
  const double point[3] = { this->Point[0]->value(), this->Point[1]->value(), -this->Point[2]->value() };
  for (int a = 0; a < 3; ++a)
  {
    position[a] += point[a] - focal[a];
  }
  vtkSMPropertyHelper(camera, "CameraFocalPoint").Set(point, 3);
  vtkSMPropertyHelper(camera, "CameraPosition").Set(position, 3);
  vtkSMPropertyHelper(camera, "CenterOfRotation").Set(point, 3);
  camera->UpdateVTKObjects();
  view->forceRender(); // the pick below names what this frame shows at the centre
  int size[2] = { 0, 0 };
  vtkSMPropertyHelper(camera, "ViewSize").Get(size, 2);
  vtkLogF(TRACE, "multiresolution go to point (%g, %g, depth %g)", point[0], point[1], -point[2]);
  pqMultiresolutionInspectActions::Pick(view, QPoint(size[0] / 2, size[1] / 2), true);
  this->Update.start();
}
