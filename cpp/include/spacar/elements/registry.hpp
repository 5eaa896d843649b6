// Factories and reference-geometry functions of the implemented element types; the catalogue
// (catalogue.cpp) attaches them to its rows. One source file per element type defines them.
#pragma once

#include <memory>
#include <vector>

#include "spacar/elements/element.hpp"
#include "spacar/errors.hpp"

namespace spacar {

// Chord length of two position nodes of dimension dim starting at x_ref[0] and x_ref[offset].
double reference_chord(const double* p, const double* q, int dim);

void reference_pltruss(const double* x_ref, const std::vector<double>& params, double& l0,
                     std::vector<double>& lgeomy);
void reference_truss(const double* x_ref, const std::vector<double>& params, double& l0,
                     std::vector<double>& lgeomy);
void reference_beam(const double* x_ref, const std::vector<double>& params, double& l0,
                    std::vector<double>& lgeomy);
void reference_plbear(const double* x_ref, const std::vector<double>& params, double& l0,
                      std::vector<double>& lgeomy);
void reference_bearing(const double* x_ref, const std::vector<double>& params, double& l0,
                       std::vector<double>& lgeomy);
void reference_plbelt(const double* x_ref, const std::vector<double>& params, double& l0,
                      std::vector<double>& lgeomy);
void reference_plbeam(const double* x_ref, const std::vector<double>& params, double& l0,
                      std::vector<double>& lgeomy);

std::unique_ptr<ElementKernel> make_truss(const ElementSetup& setup);
std::unique_ptr<ElementKernel> make_beam(const ElementSetup& setup);
std::unique_ptr<ElementKernel> make_beamnl(const ElementSetup& setup);
std::unique_ptr<ElementKernel> make_hinge(const ElementSetup& setup);
std::unique_ptr<ElementKernel> make_l2min1(const ElementSetup& setup);
std::unique_ptr<ElementKernel> make_bearing(const ElementSetup& setup);
std::unique_ptr<ElementKernel> make_surface(const ElementSetup& setup);
std::unique_ptr<ElementKernel> make_plbelt(const ElementSetup& setup);
std::unique_ptr<ElementKernel> make_plbear(const ElementSetup& setup);
std::unique_ptr<ElementKernel> make_plwheel(const ElementSetup& setup);
std::unique_ptr<ElementKernel> make_wheel(const ElementSetup& setup);
std::unique_ptr<ElementKernel> make_pltruss(const ElementSetup& setup);
std::unique_ptr<ElementKernel> make_plbeam(const ElementSetup& setup);
std::unique_ptr<ElementKernel> make_plbeamnl(const ElementSetup& setup);
std::unique_ptr<ElementKernel> make_plhinge(const ElementSetup& setup);

}  // namespace spacar
