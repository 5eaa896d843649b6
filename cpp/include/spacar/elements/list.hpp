// The element types, one line each, in catalogue order (the order of the keyword reference and
// docs/elements.md). SPACAR_ELEMENT(name) stands for the catalogue row `name_element_type()`
// that the element's source file in cpp/src/elements/ defines next to its kernel; registry.hpp
// declares them and catalogue.cpp builds the table from them. Adding an element type: its file
// and one line here (docs/adding-an-element.md).
//
// No include guard: the includer defines SPACAR_ELEMENT, includes this file, undefines it.
SPACAR_ELEMENT(beam)
SPACAR_ELEMENT(beamnl)
SPACAR_ELEMENT(beamc)
SPACAR_ELEMENT(beamw)
SPACAR_ELEMENT(truss)
SPACAR_ELEMENT(hinge)
SPACAR_ELEMENT(bearing)
SPACAR_ELEMENT(surface)
SPACAR_ELEMENT(l2min1)
SPACAR_ELEMENT(plbeam)
SPACAR_ELEMENT(plbeamnl)
SPACAR_ELEMENT(plbeamc)
SPACAR_ELEMENT(plhinge)
SPACAR_ELEMENT(pltruss)
SPACAR_ELEMENT(plbelt)
SPACAR_ELEMENT(plbear)
SPACAR_ELEMENT(plwheel)
SPACAR_ELEMENT(wheel)
