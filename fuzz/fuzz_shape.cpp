// libFuzzer target: the input opened as a shape collection (a Sweet Home 3D
// .sh3f library, a zip archive of meshes), whose members are then read and
// described, and as a labels CSV. A member that cannot be read must throw
// geods::Error (index_collection skips it); nothing may crash.
#include "fuzz_common.hpp"
#include "geods/shape/collection.hpp"

namespace {

void open_and_describe(const std::filesystem::path& p) {
  const geods::shape::ShapeCollection c = geods::shape::ShapeCollection::open(p);
  geods::shape::DescriptorOptions options = geods::shape::parse_descriptor("combined");
  options.distribution.samples = 256;
  options.distribution.bins = 8;
  geods::shape::index_collection(c, options);  // skips (and names) what it cannot read
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  geods::fuzz::read_as(data, size, "in.sh3f", open_and_describe);
  geods::fuzz::read_as(data, size, "in.zip", open_and_describe);
  geods::fuzz::read_as(data, size, "labels.csv",
                       [](const std::filesystem::path& p) { geods::shape::read_labels_csv(p); });
  return 0;
}
