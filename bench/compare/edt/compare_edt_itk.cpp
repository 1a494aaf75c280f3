// ITK's itk::SignedMaurerDistanceMapImageFilter on the edt workload: edt_256.u8 (256^3, x fastest,
// 1 = foreground). ITK measures the signed distance to the boundary of its "object"; with the
// object the mask's zeros (the background), each foreground voxel (outside the object) gets its
// distance to the nearest zero, scipy's convention, and the object's own voxels are 0 here.
// Reported like compare_edt_geods.cpp: the time (the filter's Update, on ITK's own threads,
// limited by --threads), the sum and the largest of the distances, and 5 random foreground voxels
// checked against brute force.
#include <itkImage.h>
#include <itkImportImageFilter.h>
#include <itkMultiThreaderBase.h>
#include <itkSignedMaurerDistanceMapImageFilter.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>

#include "common.hpp"

int main(int argc, char** argv) {
  const compare::Args args = compare::parse_args(argc, argv);
  if (!args.wants("256")) return 0;
  if (args.threads > 0) itk::MultiThreaderBase::SetGlobalDefaultNumberOfThreads(args.threads);
  const std::size_t n = 256;
  std::vector<std::uint8_t> mask = compare::read_raw<std::uint8_t>(args.path("edt_256.u8"));
  if (mask.size() != n * n * n) compare::die("edt_256.u8: expected 256^3 voxels");
  std::vector<std::uint8_t> object(mask.size());
  for (std::size_t i = 0; i < mask.size(); ++i) object[i] = mask[i] ? 0 : 1;  // the zeros are ITK's object

  using Image = itk::Image<std::uint8_t, 3>;
  using Distance = itk::Image<float, 3>;
  auto import = itk::ImportImageFilter<std::uint8_t, 3>::New();
  itk::ImportImageFilter<std::uint8_t, 3>::SizeType size;
  size.Fill(n);
  itk::ImportImageFilter<std::uint8_t, 3>::IndexType start;
  start.Fill(0);
  import->SetRegion(itk::ImageRegion<3>(start, size));
  import->SetImportPointer(object.data(), object.size(), false);
  import->Update();
  Image::Pointer input = import->GetOutput();

  Distance::Pointer out;
  const double s = compare::median_time_s(args.reps, [&] {
    auto filter = itk::SignedMaurerDistanceMapImageFilter<Image, Distance>::New();
    filter->SetInput(input);
    filter->SetSquaredDistance(false);
    filter->SetUseImageSpacing(true);
    filter->SetInsideIsPositive(false);  // outside the object (the mask's foreground) positive
    filter->SetBackgroundValue(0);
    filter->Update();
    out = filter->GetOutput();
  });
  const float* d = out->GetBufferPointer();
  long double sum = 0;
  double max = 0;
  for (std::size_t i = 0; i < mask.size(); ++i)
    if (mask[i]) sum += double(d[i]), max = std::max(max, double(d[i]));

  std::mt19937_64 rng(5);
  bool ok = true;
  for (int t = 0; t < 5; ++t) {
    std::size_t q;
    do q = rng() % mask.size(); while (!mask[q]);
    double best = INFINITY;
    for (std::size_t i = 0; i < mask.size(); ++i)
      if (!mask[i]) {
        const double dx = double(q % n) - double(i % n), dy = double(q / n % n) - double(i / n % n),
                     dz = double(q / (n * n)) - double(i / (n * n));
        best = std::min(best, dx * dx + dy * dy + dz * dz);
      }
    ok = ok && std::abs(double(d[q]) - std::sqrt(best)) <= 1e-5 * (1 + std::sqrt(best));  // float output
  }
  char checksum[64];
  std::snprintf(checksum, sizeof checksum, "%.2Lf / %.3f", sum, max);
  compare::Record("edt", "itk", "256", args.threads).timing(0, s, mask.size(), args.reps).set("checksum", checksum).print(ok);
  return 0;
}
