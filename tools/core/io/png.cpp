#include "io/png.h"

#include <png.h>

#include <cstring>

#include "io/error.h"
#include "io/fileio.h"

namespace skybake {

namespace {
void WriteToString(png_structp png, png_bytep data, png_size_t length) {
  auto* out = static_cast<std::string*>(png_get_io_ptr(png));
  out->append(reinterpret_cast<const char*>(data), length);
}
void FlushNothing(png_structp) {}

struct ReadState {
  const std::string* bytes;
  size_t pos;
};
void ReadFromString(png_structp png, png_bytep data, png_size_t length) {
  auto* st = static_cast<ReadState*>(png_get_io_ptr(png));
  if (st->pos + length > st->bytes->size()) png_error(png, "unexpected end of PNG data");
  std::memcpy(data, st->bytes->data() + st->pos, length);
  st->pos += length;
}
}  // namespace

std::string EncodePng8(int width, int height, int channels, const std::vector<uint8_t>& pixels) {
  SKYBAKE_CHECK(width > 0 && height > 0);
  SKYBAKE_CHECK(channels == 1 || channels == 3 || channels == 4);
  SKYBAKE_CHECK_EQ(pixels.size(), static_cast<size_t>(width) * height * channels);
  std::string out;
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_write_struct(&png, &info);
    throw InternalError("PNG encoding failed");
  }
  png_set_write_fn(png, &out, WriteToString, FlushNothing);
  const int color = channels == 1 ? PNG_COLOR_TYPE_GRAY : channels == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGBA;
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8, color,
               PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_compression_level(png, 6);
  png_write_info(png, info);
  for (int y = 0; y < height; ++y) {
    png_write_row(png, const_cast<png_bytep>(pixels.data() + static_cast<size_t>(y) * width * channels));
  }
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  return out;
}

bool WritePng8(const std::filesystem::path& path, int width, int height, int channels,
               const std::vector<uint8_t>& pixels) {
  return WriteFileIfChanged(path, EncodePng8(width, height, channels, pixels));
}

std::vector<uint8_t> DecodePng8(const std::string& bytes, const std::string& name, int* width, int* height,
                                int* channels) {
  if (bytes.size() < 8 || png_sig_cmp(reinterpret_cast<png_const_bytep>(bytes.data()), 0, 8) != 0) {
    throw InputError(FileLoc{name, 0}, "not a PNG file");
  }
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  std::vector<uint8_t> pixels;
  if (setjmp(png_jmpbuf(png))) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw InputError(FileLoc{name, 0}, "malformed PNG file");
  }
  ReadState st{&bytes, 0};
  png_set_read_fn(png, &st, ReadFromString);
  png_read_info(png, info);
  png_set_strip_16(png);
  png_set_packing(png);
  png_read_update_info(png, info);
  *width = static_cast<int>(png_get_image_width(png, info));
  *height = static_cast<int>(png_get_image_height(png, info));
  *channels = png_get_channels(png, info);
  const size_t row = png_get_rowbytes(png, info);
  pixels.resize(row * static_cast<size_t>(*height));
  for (int y = 0; y < *height; ++y) png_read_row(png, pixels.data() + row * static_cast<size_t>(y), nullptr);
  png_read_end(png, nullptr);
  png_destroy_read_struct(&png, &info, nullptr);
  return pixels;
}

}  // namespace skybake
