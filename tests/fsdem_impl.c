/* The one translation unit that holds the implementation for the test suite. */
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"
