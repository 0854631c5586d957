#pragma once
// Off-screen 3D snapshots with VTK (OpenGL). VTK 9.1 on Debian renders through GLX, so it needs an
// X display even off screen: ensure_display() uses $DISPLAY when set, else starts a private Xvfb
// (`Xvfb -displayfd`, a free display number chosen by the server) once per process, sets DISPLAY,
// and stops it at exit. Where neither works, snapshots throw cf::Error (the colon image itself
// needs no display).
#include <string>

#include "colonflat/core/mesh.h"
#include "colonflat/core/soup.h"
#include "colonflat/render/artifacts.h"

class vtkActor;
class vtkImageData;
class vtkFloatArray;
class vtkPolyData;

namespace cf {

// Returns the display in use (":N"). Throws Error when no display can be had.
std::string ensure_display();

struct SnapshotOptions {
  int width = 900, height = 900;
  std::string caption;  // drawn at the top left after the grab (caption_snapshot); empty: none
  std::string view = "anterior";  // "anterior" (from -y, LPS) or "left" (from +x)
};

// The triangles as a vtkPolyData (double points, triangle cells; point i = surface.points[i]).
vtkSmartPointer<vtkPolyData> surface_polydata(const TriangleList& surface);
// Smooth point normals as vtkPolyDataNormals makes them without splitting or reorienting: the
// sum of the unit normals of a point's triangles, normalised (zero for an unused point), as a
// float array "Normals" (#points x 3). Vertices split over the threads; the same for any count.
vtkSmartPointer<vtkFloatArray> smooth_point_normals(const TriangleList& surface);
// surface_polydata with smooth_point_normals as its point normals.
vtkSmartPointer<vtkPolyData> lit_surface_polydata(const TriangleList& surface);
// The same, bit for bit, as lit_surface_polydata(to_triangle_list(mesh)) but built straight from
// the mesh (points and normals filled once, split over the threads; the faces by core's
// mesh_triangles; no TriangleList copy of the points). A mesh with deleted elements (not garbage-collected) goes through to_triangle_list.
vtkSmartPointer<vtkPolyData> lit_surface_polydata(const Mesh& mesh);

// How a wall surface looks: diffuse colour (RGB 0-1) and specular highlight.
struct SurfaceLook {
  double color[3] = {0.88, 0.62, 0.56};
  double specular = 0.2;
  double specular_power = 20;
};
// A lit actor of the surface: its point normals when it has them (lit_surface_polydata), else
// smooth point normals from vtkPolyDataNormals (no splitting, triangle order kept); the look's
// colour and highlight. The pipeline updates when the actor is rendered.
vtkSmartPointer<vtkActor> surface_actor(vtkPolyData* surface, const SurfaceLook& look);

// The surface (LPS mm) seen from outside, with `loops` (polylines; may be null) as thick tubes
// (handles red, tunnels blue when cell data "type" is there, else orange). The scene holds no
// text: OpenGL never runs FreeType here, so a snapshot may render on one thread while another
// draws text (draw_text); the caption is drawn onto the grabbed image.
ImagePtr render_snapshot(const TriangleList& surface, vtkPolyData* loops, const SnapshotOptions& opts);
// The same for a mesh, through lit_surface_polydata(mesh): pixel for pixel the snapshot of
// to_triangle_list(surface).
ImagePtr render_snapshot(const Mesh& surface, vtkPolyData* loops, const SnapshotOptions& opts);

// Draws `caption` at the top left of a snapshot (white, 20 px; draw_text). Used by
// render_snapshot, and for a caption known only after the snapshot was rendered.
void caption_snapshot(vtkImageData* snapshot, const std::string& caption);

}  // namespace cf
