// The cross-section of an O-ring (section radius 1.5, mean radius 10) in the (r, z) plane,
// its upper half: the ring is squeezed between two identical plates, symmetric about z = 0.
a = 1.5;       // section radius
r0 = 10;       // mean radius of the ring
h = 0.1;       // element size at the mid-plane
hc = 0.03;     // element size at the top, where the plate presses
Point(1) = {r0, 0, 0, h};
Point(2) = {r0 + a, 0, 0, h};
Point(3) = {r0, a, 0, hc};
Point(4) = {r0 - a, 0, 0, h};
Circle(1) = {2, 1, 3};
Circle(2) = {3, 1, 4};
Line(3) = {4, 2};
Curve Loop(1) = {1, 2, 3};
Plane Surface(1) = {1};
Physical Surface("ring") = {1};
Physical Curve("outer") = {1, 2};
Physical Curve("midplane") = {3};
