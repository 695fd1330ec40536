#include "pm/progressive_mesh.h"
