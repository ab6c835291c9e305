// Smoke tests: each dependency links and works at run time (gmsh meshes a
// model, CGAL builds and checks a mesh, VTK writes and reads a file, yaml-cpp
// parses). Trilinos has its own MPI smoke test (smoke_trilinos.cpp).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/measure.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/generators.h>
#include <gmsh.h>
#include <gtest/gtest.h>
#include <unistd.h>
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkSphereSource.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <filesystem>
#include <numbers>

TEST(Smoke, GmshMeshesACylinder) {
  gmsh::initialize();
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::model::add("smoke");
  gmsh::model::occ::addCylinder(0, 0, 0, 0, 0, 5, 1);
  gmsh::model::occ::synchronize();
  gmsh::option::setNumber("Mesh.MeshSizeMax", 0.5);
  gmsh::model::mesh::generate(3);
  std::vector<int> types;
  std::vector<std::vector<std::size_t>> tags, nodes;
  gmsh::model::mesh::getElements(types, tags, nodes, 3);
  gmsh::finalize();
  ASSERT_EQ(types.size(), 1u);
  EXPECT_EQ(types[0], 4);  // tetrahedra
  EXPECT_GT(tags[0].size(), 100u);
}

TEST(Smoke, CgalBuildsAClosedMesh) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  CGAL::Surface_mesh<K::Point_3> mesh;
  CGAL::make_tetrahedron(K::Point_3(0, 0, 0), K::Point_3(1, 0, 0), K::Point_3(0, 1, 0), K::Point_3(0, 0, 1), mesh);
  EXPECT_TRUE(CGAL::is_closed(mesh));
  EXPECT_NEAR(std::abs(CGAL::Polygon_mesh_processing::volume(mesh)), 1.0 / 6.0, 1e-12);
}

TEST(Smoke, VtkWritesAndReadsAFile) {
  const auto file = std::filesystem::temp_directory_path() / ("stentsim-smoke-" + std::to_string(::getpid()) + ".vtp");
  vtkNew<vtkSphereSource> sphere;
  sphere->SetThetaResolution(16);
  sphere->SetPhiResolution(8);
  sphere->Update();
  vtkNew<vtkXMLPolyDataWriter> w;
  w->SetFileName(file.c_str());
  w->SetInputData(sphere->GetOutput());
  ASSERT_EQ(w->Write(), 1);
  vtkNew<vtkXMLPolyDataReader> r;
  r->SetFileName(file.c_str());
  r->Update();
  EXPECT_EQ(r->GetOutput()->GetNumberOfPoints(), sphere->GetOutput()->GetNumberOfPoints());
  EXPECT_GT(r->GetOutput()->GetNumberOfPoints(), 0);
  std::filesystem::remove(file);
}

TEST(Smoke, YamlParses) {
  auto n = YAML::Load("balloon: {length: 9.4, elements: [29, 44]}");
  EXPECT_DOUBLE_EQ(n["balloon"]["length"].as<double>(), 9.4);
  EXPECT_EQ(n["balloon"]["elements"][1].as<int>(), 44);
}
