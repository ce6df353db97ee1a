// The readout of a Multiresolution Surface as the GUI components see it.
#ifndef pqMultiresolutionReadout_h
#define pqMultiresolutionReadout_h

#include <QString>

class pqRepresentation;
class vtkSMProxy;

struct pqMultiresolutionReadout
{
  double Tolerance = 0;       ///< px, of the last frame
  double EstimatedError = 0;  ///< px, the last frame's estimated error
  double TargetFrameRate = 0; ///< 0: fixed tolerance
  double RenderScale = 1;     ///< of the last frame: below 1 while moving frames are reduced
  bool Moving = false;        ///< the last frame used the frame-rate controller's tolerance
  double ResidentMB = 0;
  int BudgetMB = 0;
  double Triangles = 0;
  int Regions = 0;
  int Substituted = 0;
  double FrameMs = 0;
  bool LoadsPending = false;
  double RefreshWaitMs = 30; ///< while loads are pending, the wait before the next refresh
  QString Error;

  /// The Multiresolution Surface sub-proxy of a representation shown as one, else nullptr.
  static vtkSMProxy* Surface(pqRepresentation* representation, bool visibleOnly);
  /// Pulls the readout (from the render server, see vtkSMMultiresolutionSurfaceRepresentationProxy).
  static pqMultiresolutionReadout Pull(vtkSMProxy* surface);
};

#endif
