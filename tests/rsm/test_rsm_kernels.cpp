#include <bounce/rsm.hpp>
