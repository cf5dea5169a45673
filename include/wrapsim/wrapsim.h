/**
 * @file wrapsim.h
 * @brief libwrapsim: simulation of stretch-wrapped loads. Include this one header.
 */
#ifndef WRAPSIM_WRAPSIM_H
#define WRAPSIM_WRAPSIM_H

#include <wrapsim/version.h>
#include <wrapsim/common.h>
#include <wrapsim/world.h>
#include <wrapsim/shape.h>
#include <wrapsim/body.h>
#include <wrapsim/contact.h>
#include <wrapsim/law.h>
#include <wrapsim/web.h>
#include <wrapsim/element.h>
#include <wrapsim/io.h>
#include <wrapsim/loadtest.h>

#endif
