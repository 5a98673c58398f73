// A block with a bore under its top face, indented by a rigid sphere (3D). A point embedded
// at the centre of the top face carries the small element size; sizes grow away from it.
SetFactory("OpenCASCADE");
Box(1) = {-0.6, -0.6, 0, 1.2, 1.2, 0.6};
Cylinder(2) = {-0.6, 0, 0.35, 1.2, 0, 0, 0.12};
BooleanDifference(3) = {Volume{1}; Delete;}{Volume{2}; Delete;};
eps = 1e-6;
top() = Surface In BoundingBox{-1, -1, 0.6 - eps, 1, 1, 0.6 + eps};
Point(100) = {0, 0, 0.6};
Point{100} In Surface{top(0)};
MeshSize{:} = 0.12;
MeshSize{100} = 0.015;
Physical Volume("block") = {3};
Physical Surface("bottom") = Surface In BoundingBox{-1, -1, -eps, 1, 1, eps};
Physical Surface("top") = {top()};
