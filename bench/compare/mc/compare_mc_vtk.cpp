// VTK 9 on the mc comparison: vtkFlyingEdges3D, or with MC_VTK_MARCHING_CUBES vtkMarchingCubes;
// no normals, gradients or scalars. The volume is wrapped (no copy) in a vtkImageData before
// timing; each repetition runs a fresh filter. Threads: vtkSMPTools (flying edges only;
// vtkMarchingCubes is sequential).
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkSMPTools.h>
#include <vtkSmartPointer.h>

#ifdef MC_VTK_MARCHING_CUBES
#include <vtkMarchingCubes.h>
using Filter = vtkMarchingCubes;
constexpr const char* kAnchor = "vtk-marchingcubes";
#else
#include <vtkFlyingEdges3D.h>
using Filter = vtkFlyingEdges3D;
constexpr const char* kAnchor = "vtk-flyingedges";
#endif

#include "mc_driver.hpp"

int main(int argc, char** argv) {
  const compare::Args args = compare::parse_args(argc, argv);
  vtkSMPTools::Initialize(args.threads);
  std::vector<float> volume = compare::mc::load_volume(args);
  const int n = int(compare::mc::kSide);
  auto scalars = vtkSmartPointer<vtkFloatArray>::New();
  scalars->SetArray(volume.data(), vtkIdType(volume.size()), 1);  // 1: VTK does not free it
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(n, n, n);
  image->GetPointData()->SetScalars(scalars);
  return compare::mc::run(
      argc, argv, kAnchor, [] { return 0.0; },
      [&](double iso) {
        auto filter = vtkSmartPointer<Filter>::New();
        filter->SetInputData(image);
        filter->SetValue(0, iso);
        filter->ComputeNormalsOff();
        filter->ComputeGradientsOff();
        filter->ComputeScalarsOff();
        filter->Update();
        vtkPolyData* out = filter->GetOutput();
        return compare::mc::Extracted{std::size_t(out->GetNumberOfPoints()), std::size_t(out->GetNumberOfPolys()), 0};
      });
}
