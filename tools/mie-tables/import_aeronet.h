// `mie-tables import-aeronet`: the files written for one AERONET retrieval (docs/mie.md,
// "Importing an AERONET inversion"): a particle type of one tabulated mode with the retrieval's
// refractive-index points, its size table (CSV with its source line), and the aerosol layer's
// scale (the optical depth at 550 nm). Texts only: the caller writes them, after every check.
#pragma once

#include <string>

#include "optics/aeronet_inversion.h"

namespace skybake::mietool {

struct ImportedType {
  std::string particle_yaml;  // NAME.yaml
  std::string size_csv;       // NAME_size_distribution.csv (named in the YAML)
  std::string layer_yaml;     // the `scale:` of an atmosphere's aerosol layer
};

// `name` is the type's name (the file stem), `csv_name` the size table's file name beside it.
ImportedType ImportAeronet(const mie::AeronetRetrieval& r, const std::string& name, const std::string& csv_name);

}  // namespace skybake::mietool
