/* validation/fsdem_impl.c - the implementation of fsdem.h for the validation cases, compiled once
   (build/validation/fsdem_impl.o); each case includes fsdem.h without FSDEM_IMPLEMENTATION and links
   against it (validation/common.h says how to build a case by hand). */
#define FSDEM_IMPLEMENTATION
#include "fsdem.h"
