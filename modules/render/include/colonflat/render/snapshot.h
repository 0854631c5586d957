#pragma once
// Off-screen 3D snapshots with VTK (OpenGL). VTK 9.1 on Debian renders through GLX, so it needs an
// X display even off screen: ensure_display() uses $DISPLAY when set, else starts a private Xvfb
// (`Xvfb -displayfd`, a free display number chosen by the server) once per process, sets DISPLAY,
// and stops it at exit. Where neither works, snapshots throw cf::Error (the colon image itself
// needs no display).
#include <string>

#include "colonflat/core/soup.h"
#include "colonflat/render/artifacts.h"

namespace cf {

// Returns the display in use (":N"). Throws Error when no display can be had.
std::string ensure_display();

struct SnapshotOptions {
  int width = 900, height = 900;
  std::string caption;
  std::string view = "anterior";  // "anterior" (from -y, LPS) or "left" (from +x)
};

// The surface (LPS mm) seen from outside, with `loops` (polylines; may be null) as thick tubes
// (handles red, tunnels blue when cell data "type" is there, else orange).
ImagePtr render_snapshot(const TriangleList& surface, vtkPolyData* loops, const SnapshotOptions& opts);

}  // namespace cf
