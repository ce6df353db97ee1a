#include "pqMultiresolutionInspectActions.h"

#include "pqMultiresolutionReadout.h"

#include "pqActiveObjects.h"
#include "pqPipelineSource.h"
#include "pqRenderView.h"
#include "pqServer.h"
#include "vtkCommand.h"
#include "vtkLogger.h"
#include "vtkNew.h"
#include "vtkRenderWindowInteractor.h"
#include "vtkSMParaViewPipelineControllerWithRendering.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxy.h"
#include "vtkSMRenderViewProxy.h"
#include "vtkSMSessionProxyManager.h"
#include "vtkSMSourceProxy.h"
#include "vtkSmartPointer.h"

#include <QKeySequence>
#include <QLocale>
#include <QToolTip>
#include <QWidget>

#include <cmath>

namespace
{
QString Selected;
const char* OutlineName = "Selected Cell";

/// The Multiresolution Surface shown in `view` (the first visible one), else nullptr.
vtkSMProxy* SurfaceIn(pqView* view)
{
  for (int i = 0; view && i < view->getNumberOfRepresentations(); ++i)
  {
    if (vtkSMProxy* surface = pqMultiresolutionReadout::Surface(view->getRepresentation(i), true))
    {
      return surface;
    }
  }
  return nullptr;
}

/// Each line NAME=value of PickedValues, the colour array's first.
QStringList ValueLines(vtkSMProxy* surface)
{
  const QString all = QString::fromUtf8(vtkSMPropertyHelper(surface, "PickedValues").GetAsString());
  const char* colored = vtkSMPropertyHelper(surface, "ColorArrayName").GetInputArrayNameToProcess();
  QStringList lines = all.split('\n', Qt::SkipEmptyParts);
  for (int n = 0; colored && n < lines.size(); ++n)
  {
    if (lines[n].startsWith(QString::fromUtf8(colored) + "="))
    {
      lines.move(n, 0);
      break;
    }
  }
  return lines;
}
} // namespace

pqMultiresolutionInspectActions::pqMultiresolutionInspectActions(QObject* parent)
  : Superclass(parent)
{
  this->setExclusive(false);
  this->Inspect = this->addAction(tr("Inspect Cells"));
  this->Inspect->setCheckable(true);
  this->Inspect->setObjectName("actionInspectCells");
  this->Inspect->setShortcut(QKeySequence(tr("Ctrl+Shift+I")));
  this->Inspect->setShortcutContext(Qt::ApplicationShortcut);
  this->Inspect->setToolTip(tr("Multiresolution Surface: rest the cursor on a cell to see its I, J, K and values; "
                               "click to select it (Ctrl+Shift+I)"));
  QObject::connect(this->Inspect, &QAction::toggled, this, &pqMultiresolutionInspectActions::setOn);
  this->Hover.setSingleShot(true);
  this->Hover.setInterval(300);
  QObject::connect(&this->Hover, &QTimer::timeout, this, &pqMultiresolutionInspectActions::pickHovered);
  QObject::connect(
    &pqActiveObjects::instance(), &pqActiveObjects::viewChanged, this, &pqMultiresolutionInspectActions::setView);
}

pqMultiresolutionInspectActions::~pqMultiresolutionInspectActions()
{
  this->Observe(false);
}

QString pqMultiresolutionInspectActions::SelectedText()
{
  return Selected;
}

void pqMultiresolutionInspectActions::setOn(bool on)
{
  vtkLogF(TRACE, "multiresolution inspect cells: %s", on ? "on" : "off");
  this->Observe(false);
  this->View = on ? qobject_cast<pqRenderView*>(pqActiveObjects::instance().activeView()) : nullptr;
  this->Observe(on);
  if (!on)
  {
    this->Hover.stop();
    QToolTip::hideText();
  }
}

void pqMultiresolutionInspectActions::setView(pqView*)
{
  this->setOn(this->Inspect->isChecked());
}

void pqMultiresolutionInspectActions::Observe(bool on)
{
  vtkRenderWindowInteractor* interactor = this->View ? this->View->getRenderViewProxy()->GetInteractor() : nullptr;
  if (!interactor)
  {
    return;
  }
  const unsigned long events[3] = { vtkCommand::MouseMoveEvent, vtkCommand::LeftButtonPressEvent,
    vtkCommand::LeftButtonReleaseEvent };
  for (int n = 0; n < 3; ++n)
  {
    if (on)
    {
      // Passive observers: the camera's interaction still gets every event.
      this->Observers[n] = interactor->AddObserver(events[n], this, &pqMultiresolutionInspectActions::OnMouse, -1.0f);
    }
    else if (this->Observers[n])
    {
      interactor->RemoveObserver(this->Observers[n]);
      this->Observers[n] = 0;
    }
  }
}

void pqMultiresolutionInspectActions::OnMouse(vtkObject* caller, unsigned long event, void*)
{
  auto* interactor = vtkRenderWindowInteractor::SafeDownCast(caller);
  const int* position = interactor->GetEventPosition();
  this->At = QPoint(position[0], position[1]);
  if (event == vtkCommand::LeftButtonPressEvent)
  {
    this->ButtonDown = true;
    this->Pressed = this->At;
    this->Hover.stop();
  }
  else if (event == vtkCommand::LeftButtonReleaseEvent)
  {
    this->ButtonDown = false;
    if (this->At == this->Pressed)
    {
      Pick(this->View, this->At, true); // a click, not a drag
    }
  }
  else if (!this->ButtonDown)
  {
    QToolTip::hideText();
    this->Hover.start();
  }
}

void pqMultiresolutionInspectActions::pickHovered()
{
  const QString text = Pick(this->View, this->At, false);
  QWidget* widget = this->View ? this->View->widget() : nullptr;
  if (!widget || text.isEmpty())
  {
    return;
  }
  const double ratio = widget->devicePixelRatioF();
  const QPoint local(qRound(this->At.x() / ratio), widget->height() - qRound(this->At.y() / ratio));
  QToolTip::showText(widget->mapToGlobal(local), text, widget);
}

QString pqMultiresolutionInspectActions::Pick(pqRenderView* view, const QPoint& at, bool select)
{
  vtkSMProxy* surface = SurfaceIn(view);
  if (!surface)
  {
    return QString();
  }
  // Answered at once from the frame on screen (no render), where the surface renders.
  surface->UpdatePropertyInformation();
  const int done = vtkSMPropertyHelper(surface, "PicksDone").GetAsInt();
  vtkSMPropertyHelper(surface, "PickAt").Set(0, at.x());
  vtkSMPropertyHelper(surface, "PickAt").Set(1, at.y());
  surface->UpdateVTKObjects();
  surface->UpdatePropertyInformation();
  if (vtkSMPropertyHelper(surface, "PicksDone").GetAsInt() == done)
  {
    view->forceRender(); // no frame drawn yet
    surface->UpdatePropertyInformation();
  }
  vtkSMPropertyHelper(surface, "PickAt").Set(0, -1);
  vtkSMPropertyHelper(surface, "PickAt").Set(1, -1);
  surface->UpdateVTKObjects();
  std::vector<double> corners;
  const QString text = Describe(surface, corners);
  vtkLogF(TRACE, "multiresolution pick at (%d, %d): %s", at.x(), at.y(),
    text.isEmpty() ? "nothing" : text.split('\n').first().toUtf8().constData());
  if (select)
  {
    Select(view, text, corners);
  }
  return text;
}

QString pqMultiresolutionInspectActions::Describe(vtkSMProxy* surface, std::vector<double>& corners)
{
  corners.clear();
  int cell[3] = { 0, 0, 0 };
  vtkSMPropertyHelper(surface, "PickedCell").Get(cell, 3);
  if (cell[0] <= 0)
  {
    return QString();
  }
  const int active = vtkSMPropertyHelper(surface, "PickedActive").GetAsInt();
  QString text = tr("Cell I %1, J %2, K %3 (%4)")
                   .arg(cell[0])
                   .arg(cell[1])
                   .arg(cell[2])
                   .arg(active > 0   ? tr("active")
                       : active == 0 ? tr("inactive")
                                     : tr("no active cell in its column"));
  if (active >= 0)
  {
    corners.resize(24);
    vtkSMPropertyHelper(surface, "PickedCorners").Get(corners.data(), 24);
    double depth = 0;
    for (int c = 0; c < 8; ++c)
    {
      depth -= corners[3 * c + 2] / 8;
    }
    text += "\n" + tr("Depth %1").arg(depth, 0, 'f', 2);
  }
  for (const QString& line : ValueLines(surface))
  {
    text += "\n" + QString(line).replace("=", " = ");
  }
  return text;
}

void pqMultiresolutionInspectActions::Select(
  pqRenderView* view, const QString& text, const std::vector<double>& corners)
{
  vtkLogF(TRACE, "multiresolution selected: %s", text.isEmpty() ? "nothing" : text.toUtf8().constData());
  Selected = text;
  // The selected cell's edges as a poly-line source, replaced at each selection.
  pqServer* server = pqActiveObjects::instance().activeServer();
  if (!server || !view)
  {
    return;
  }
  vtkSMSessionProxyManager* proxies = server->proxyManager();
  vtkNew<vtkSMParaViewPipelineControllerWithRendering> controller;
  // The outline is no pipeline step of the user's: the active source stays what it was.
  pqActiveObjects& active = pqActiveObjects::instance();
  QPointer<pqPipelineSource> previous = active.activeSource();
  if (vtkSMProxy* old = proxies->GetProxy("sources", OutlineName))
  {
    controller->UnRegisterProxy(old);
  }
  if (corners.size() != 24 || !std::isfinite(corners[0]))
  {
    view->render();
    return;
  }
  static const int path[16] = { 0, 1, 3, 2, 0, 4, 5, 7, 6, 4, 5, 1, 3, 7, 6, 2 }; // every edge
  std::vector<double> points;
  for (int n : path)
  {
    points.insert(points.end(), corners.begin() + 3 * n, corners.begin() + 3 * n + 3);
  }
  vtkSmartPointer<vtkSMProxy> line;
  line.TakeReference(proxies->NewProxy("sources", "PolyLineSource"));
  if (!line)
  {
    return;
  }
  controller->PreInitializeProxy(line);
  vtkSMPropertyHelper(line, "Points").Set(points.data(), static_cast<unsigned int>(points.size()));
  controller->PostInitializeProxy(line);
  controller->RegisterPipelineProxy(line, OutlineName);
  vtkSMProxy* shown =
    controller->Show(vtkSMSourceProxy::SafeDownCast(line), 0, vtkSMViewProxy::SafeDownCast(view->getProxy()));
  if (shown)
  {
    const double red[3] = { 1.0, 0.1, 0.1 };
    vtkSMPropertyHelper(shown, "AmbientColor").Set(red, 3);
    vtkSMPropertyHelper(shown, "DiffuseColor").Set(red, 3);
    vtkSMPropertyHelper(shown, "LineWidth").Set(3.0);
    shown->UpdateVTKObjects();
  }
  if (previous)
  {
    active.setActiveSource(previous);
  }
  view->render();
}
