namespace finecap {
struct Config;
int RunRefine(const Config&) { return 0; }
}  // namespace finecap
