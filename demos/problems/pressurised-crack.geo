// A straight crack of half-length 1 inside a 20 x 20 plate (an interior line the mesh follows;
// the two faces share their nodes, the enrichment opens them). Elements of 0.02 along the
// crack, 0.004 at its tips, 1 at the plate's edges.
W = 10;
a = 1;
Point(1) = {-W, -W, 0, 1.0};
Point(2) = {W, -W, 0, 1.0};
Point(3) = {W, W, 0, 1.0};
Point(4) = {-W, W, 0, 1.0};
Line(1) = {1, 2};
Line(2) = {2, 3};
Line(3) = {3, 4};
Line(4) = {4, 1};
Point(5) = {-a, 0, 0, 0.004};
Point(6) = {0, 0, 0, 0.02};
Point(7) = {a, 0, 0, 0.004};
Line(5) = {5, 6};
Line(6) = {6, 7};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Line{5, 6} In Surface{1};
Physical Surface("plate") = {1};
Physical Curve("bottom") = {1};
Physical Curve("left") = {4};
Physical Curve("top") = {3};
Physical Curve("crack") = {5, 6};
