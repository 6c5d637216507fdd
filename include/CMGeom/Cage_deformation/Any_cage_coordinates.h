// Copyright (c) 2026 CMGeom contributors.
// SPDX-License-Identifier: GPL-3.0-or-later
//
// Any_cage_coordinates: a type-erased CageCoordinates model (Cage_coordinates.h). A *Cages system
// (thesis §5.3.3) lets every cage use its own coordinate type, chosen at run time from a file, so
// the system stores its cages' coordinates behind this one interface; make_cage_coordinates()
// builds the model of a Coordinate_type. Evaluation costs one virtual call per query on top of the
// wrapped model's O(n + m).
#ifndef CMGEOM_CAGE_DEFORMATION_ANY_CAGE_COORDINATES_H
#define CMGEOM_CAGE_DEFORMATION_ANY_CAGE_COORDINATES_H

#include <CMGeom/Cage_deformation/Cage_system_description.h>
#include <CMGeom/Cage_deformation/Green_coordinates_3.h>
#include <CMGeom/Cage_deformation/Harmonic_coordinates_3.h>
#include <CMGeom/Cage_deformation/Mean_value_coordinates_3.h>

#include <iterator>
#include <memory>
#include <utility>
#include <vector>

namespace CMGeom {
namespace Cage_deformation {

class Any_cage_coordinates {
  struct Concept {
    virtual ~Concept() = default;
    virtual std::size_t size() const = 0;
    virtual Coordinate_status eval(const Vec3& q, double* out) const = 0;
    virtual void basis(const std::vector<Vec3>& deformed, std::vector<Vec3>& out) const = 0;
    virtual const Triangle_cage& cage() const = 0;
  };
  template <class C>
  struct Model final : Concept {
    explicit Model(C c) : c_(std::move(c)), rule_(c_.deformation_rule()) {}
    std::size_t size() const override { return c_.number_of_coordinates(); }
    Coordinate_status eval(const Vec3& q, double* out) const override { return c_(q, out); }
    void basis(const std::vector<Vec3>& d, std::vector<Vec3>& out) const override {
      out.clear();
      rule_(d, std::back_inserter(out));
    }
    const Triangle_cage& cage() const override { return c_.cage(); }
    C c_;
    decltype(std::declval<const C&>().deformation_rule()) rule_;
  };

public:
  /// Rule of the wrapped model, itself a CageDeformationRule.
  class Rule {
  public:
    explicit Rule(std::shared_ptr<const Concept> p) : p_(std::move(p)) {}
    std::size_t number_of_coordinates() const { return p_->size(); }
    template <class OutputIterator>
    void operator()(const std::vector<Vec3>& deformed, OutputIterator out) const {
      std::vector<Vec3> b;
      p_->basis(deformed, b);
      for (const Vec3& x : b) *out++ = x;
    }

  private:
    std::shared_ptr<const Concept> p_;
  };

  Any_cage_coordinates() = default;
  template <class C>
  explicit Any_cage_coordinates(C c) : p_(std::make_shared<Model<C>>(std::move(c))) {}

  std::size_t number_of_coordinates() const { return p_->size(); }
  const Triangle_cage& cage() const { return p_->cage(); }
  Rule deformation_rule() const { return Rule(p_); }

  /// Writes number_of_coordinates() values to `out` (a double*).
  Coordinate_status evaluate(const Vec3& q, double* out) const { return p_->eval(q, out); }
  template <class Point, class OutputIterator>
  Coordinate_status operator()(const Point& q, OutputIterator out) const {
    std::vector<double> w(p_->size());
    const Coordinate_status s = p_->eval(internal::to_vec3(q), w.data());
    for (double x : w) *out++ = x;
    return s;
  }
  /// Basis vectors of a deformed pose (allocation-free when `out` has the capacity).
  void basis(const std::vector<Vec3>& deformed, std::vector<Vec3>& out) const { p_->basis(deformed, out); }

private:
  std::shared_ptr<const Concept> p_;
};

/// The coordinates of `type` on a validated cage (harmonic ones are solved here).
inline Any_cage_coordinates make_cage_coordinates(Coordinate_type type, const Triangle_cage& cage,
                                                  const Harmonic_options& harmonic = Harmonic_options()) {
  switch (type) {
    case Coordinate_type::green:
      return Any_cage_coordinates(Green_coordinates_3(cage));
    case Coordinate_type::harmonic:
      return Any_cage_coordinates(Harmonic_coordinates_3(cage, harmonic));
    case Coordinate_type::mean_value:
      break;
  }
  return Any_cage_coordinates(Mean_value_coordinates_3(cage));
}

}  // namespace Cage_deformation
}  // namespace CMGeom

#endif  // CMGEOM_CAGE_DEFORMATION_ANY_CAGE_COORDINATES_H
