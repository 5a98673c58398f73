// A shrink fit: a ring (radii a = 1, b = 1.5) inside a ring whose bore is delta = 0.005 smaller
// (b - delta, c = 2), a quarter of each, meshed independently (the bore h, the inner ring 0.7 h:
// non-matching curved contact lines), 2D plane strain. The overlap at the start is the fit's.
a = 1.0; b = 1.5; c = 2.0; d = 0.005;
h = 0.025;
Point(1) = {0, 0, 0};
Point(2) = {a, 0, 0, 0.7 * h}; Point(3) = {b, 0, 0, 0.7 * h};
Point(4) = {0, b, 0, 0.7 * h}; Point(5) = {0, a, 0, 0.7 * h};
Line(1) = {2, 3}; Circle(2) = {3, 1, 4}; Line(3) = {4, 5}; Circle(4) = {5, 1, 2};
Curve Loop(1) = {1, 2, 3, 4}; Plane Surface(1) = {1};
Point(12) = {b - d, 0, 0, h}; Point(13) = {c, 0, 0, h};
Point(14) = {0, c, 0, h}; Point(15) = {0, b - d, 0, h};
Line(11) = {12, 13}; Circle(12) = {13, 1, 14}; Line(13) = {14, 15}; Circle(14) = {15, 1, 12};
Curve Loop(2) = {11, 12, 13, 14}; Plane Surface(2) = {2};
Physical Surface("inner") = {1};
Physical Surface("outer") = {2};
Physical Curve("inner_surface") = {2};
Physical Curve("bore") = {14};
Physical Curve("symmetry_x") = {3, 13};   // on x = 0: rollers in x
Physical Curve("symmetry_y") = {1, 11};   // on y = 0: rollers in y
