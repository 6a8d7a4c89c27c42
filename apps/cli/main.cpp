// follicle: command-line front end. (Placeholder until the CLI lands.)
#include <cstdio>

int main() {
  std::puts("follicle");
  return 0;
}
