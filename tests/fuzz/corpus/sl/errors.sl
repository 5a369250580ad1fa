surface broken( { float x = ; if ( Ci = 
#if
#define
#include "nothere.h"
