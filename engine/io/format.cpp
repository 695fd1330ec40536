#include "io/mesh_io.h"
